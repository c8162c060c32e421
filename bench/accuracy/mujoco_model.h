// An MJCF model compiled by MuJoCo (only in the benchmarks; the product never links MuJoCo): the
// accuracy benchmark's scenes and the cube tosses build their XML and compile it here.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

namespace collision_response::bench {

/// A number as MJCF reads it back to the last bit.
inline std::string mjcfNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

/// A compiled model and its data.
struct MujocoModel {
  std::unique_ptr<mjModel, void (*)(mjModel*)> model{nullptr, mj_deleteModel};
  std::unique_ptr<mjData, void (*)(mjData*)> data{nullptr, mj_deleteData};
};

/// Compiles `xml` through MuJoCo's virtual file system (as the file `name`); throws with
/// MuJoCo's error and the XML when it does not compile.
inline std::shared_ptr<MujocoModel> compileMjcf(const std::string& xml,
                                                const std::string& name = "model.xml") {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("MuJoCo: cannot make the virtual model file");
  }
  const int file = mj_findFileVFS(vfs.get(), name.c_str());
  std::memcpy(vfs->filedata[file], xml.data(), xml.size());
  char error[1000] = "";
  auto compiled = std::make_shared<MujocoModel>();
  compiled->model.reset(mj_loadXML(name.c_str(), vfs.get(), error, sizeof error));
  mj_deleteVFS(vfs.get());
  if (!compiled->model) throw std::runtime_error(std::string("MuJoCo: ") + error + "\n" + xml);
  compiled->data.reset(mj_makeData(compiled->model.get()));
  return compiled;
}

}  // namespace collision_response::bench

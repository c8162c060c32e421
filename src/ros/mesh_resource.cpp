#include "collision_response/ros/mesh_resource.h"

#include <fcntl.h>
#include <geometric_shapes/mesh_operations.h>
#include <geometric_shapes/shapes.h>
#include <ros/package.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <memory>
#include <new>
#include <sstream>

#include "collision_response/core/validation.h"
#include "collision_response/ros/parameters.h"

namespace collision_response {
namespace {

const std::string kPackageScheme = "package://";
const std::string kFileScheme = "file://";

bool startsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

/// An error whose reason alone is used (the caller names the key).
core::Error failure(const std::string& reason) { return core::Error{"", reason}; }

std::string kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string tooLarge(std::size_t max_bytes) {
  return "more than max_mesh_bytes (" + std::to_string(max_bytes) +
         ", the scene's limit on a mesh file: raise it for a larger mesh)";
}

/// Closes a descriptor when it leaves scope.
struct FileDescriptor {
  int fd;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

/// How many of `scaled`'s zero-area triangles had an area unscaled (`unscaled`): both ascending.
std::size_t vanished(const std::vector<std::size_t>& scaled,
                     const std::vector<std::size_t>& unscaled) {
  std::vector<std::size_t> only_scaled;
  std::set_difference(scaled.begin(), scaled.end(), unscaled.begin(), unscaled.end(),
                      std::back_inserter(only_scaled));
  return only_scaled.size();
}

}  // namespace

core::Expected<std::string> meshResourcePath(const std::string& resource) {
  if (startsWith(resource, kFileScheme)) {
    const std::string path = resource.substr(kFileScheme.size());
    if (path.empty() || path[0] != '/') {
      return failure("is not a file:// address of an absolute path (file:///home/me/grip.stl)");
    }
    return path;
  }
  if (startsWith(resource, kPackageScheme)) {
    const std::string rest = resource.substr(kPackageScheme.size());
    const std::size_t slash = rest.find('/');
    const std::string package = rest.substr(0, slash);
    if (package.empty() || slash == std::string::npos || slash + 1 == rest.size()) {
      return failure("is not a package://<package>/<path> address");
    }
    const std::string directory = ros::package::getPath(package);
    if (directory.empty()) {
      return failure("does not load: no package '" + package +
                     "' (is its workspace's setup.bash sourced?)");
    }
    // As resource_retriever resolves it: the rest of the address, from its slash, in the package.
    return directory + rest.substr(slash);
  }
  const std::size_t scheme_end = resource.find("://");
  if (scheme_end == std::string::npos) {
    return failure(
        "is not an address: a mesh is a package://<package>/<path> or file:///<path> address");
  }
  return failure("has the scheme " + resource.substr(0, scheme_end + 3) +
                 ", which is not read: a mesh is a package:// or file:// address, a file on this "
                 "machine (nothing is fetched over a network, where a server that never answers "
                 "would hold the start-up)");
}

core::Expected<std::string> readMeshFile(const std::string& path, std::size_t max_bytes) {
  // Looked at before it is opened: opening a FIFO would wait for a writer, a device may act.
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) {
    return failure("does not load: " + std::string(std::strerror(errno)) + " (" + path + ")");
  }
  if (!S_ISREG(status.st_mode)) {
    return failure("is " + kindOf(status.st_mode) + " (" + path +
                   "), not a regular file: a mesh is read from a file");
  }
  // Opened without waiting, and looked at again: the path may have changed in between.
  const FileDescriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (file.fd < 0 || ::fstat(file.fd, &status) != 0) {
    return failure("does not load: " + std::string(std::strerror(errno)) + " (" + path + ")");
  }
  if (!S_ISREG(status.st_mode)) {
    return failure("is " + kindOf(status.st_mode) + " (" + path +
                   "), not a regular file: a mesh is read from a file");
  }
  const auto size = static_cast<std::size_t>(status.st_size);
  if (size > max_bytes) {
    return failure("is " + std::to_string(size) + " bytes (" + path + "), " + tooLarge(max_bytes));
  }
  // Read up to one byte past the limit: a file that grows as it is read (or whose size stat does
  // not know, as /proc's) is refused as soon as it passes it.
  std::string bytes(size + 1, '\0');
  std::size_t filled = 0;
  for (;;) {
    if (filled == bytes.size()) {
      if (bytes.size() > max_bytes) {
        return failure("grew past " + std::to_string(max_bytes) + " bytes as it was read (" + path +
                       "), " + tooLarge(max_bytes));
      }
      bytes.resize(std::min(2 * bytes.size(), max_bytes + 1));
    }
    const ssize_t got = ::read(file.fd, &bytes[filled], bytes.size() - filled);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      return failure("does not load: " + std::string(std::strerror(errno)) + " (" + path + ")");
    }
    if (got == 0) break;
    filled += static_cast<std::size_t>(got);
  }
  bytes.resize(filled);
  return bytes;
}

namespace {

core::Expected<std::shared_ptr<const core::TriangleMesh>> loadWithinMemory(
    const std::string& resource, const Eigen::Vector3d& scale, const std::string& field,
    std::vector<std::string>& warnings, std::size_t max_bytes) {
  const std::string scale_field = joinKey(field, "scale");
  for (int i = 0; i < 3; ++i) {
    if (!(std::isfinite(scale[i]) && scale[i] > 0)) {
      std::ostringstream got;
      got << scale[i];
      return core::Error{
          indexKey(scale_field, static_cast<std::size_t>(i)),
          "must be finite and > 0 (the mesh's size along its own axis), got " + got.str()};
    }
  }
  const std::string resource_field = joinKey(field, "resource");
  if (resource.empty()) {
    return core::Error{resource_field, "is required (a package:// or file:// address)"};
  }
  const auto named = [&](const core::Error& error) {
    return core::Error{resource_field, "'" + resource + "' " + error.reason};
  };
  const auto path = meshResourcePath(resource);
  if (!path) return named(path.error());
  const auto bytes = readMeshFile(*path, max_bytes);
  if (!bytes) return named(bytes.error());
  if (bytes->empty()) return core::Error{resource_field, "'" + resource + "' is empty"};
  // geometric_shapes hands the bytes to assimp, which takes the format from the name's extension.
  // Read at scale 1, and scaled below: a scale the doubles cannot take is then told from a file
  // without triangles.
  const std::unique_ptr<shapes::Mesh> loaded(shapes::createMeshFromBinary(
      bytes->data(), bytes->size(), Eigen::Vector3d::Ones(), resource));
  if (!loaded || loaded->triangle_count == 0) {
    return core::Error{resource_field, "'" + resource +
                                           "' is not a mesh assimp reads (STL, COLLADA, OBJ, ...)"
                                           " or has no triangle; assimp's reason is in the log"};
  }
  std::vector<Eigen::Vector3d> unscaled(loaded->vertex_count), vertices(loaded->vertex_count);
  Eigen::Vector3d low = Eigen::Vector3d::Constant(INFINITY), high = -low;
  for (unsigned int v = 0; v < loaded->vertex_count; ++v) {
    unscaled[v] = Eigen::Vector3d(loaded->vertices[3 * v], loaded->vertices[3 * v + 1],
                                  loaded->vertices[3 * v + 2]);
    // As geometric_shapes scales a vertex (each coordinate times the scale, in doubles).
    vertices[v] = unscaled[v].cwiseProduct(scale);
    low = low.cwiseMin(unscaled[v]);
    high = high.cwiseMax(unscaled[v]);
  }
  std::vector<core::TriangleMesh::Triangle> triangles(loaded->triangle_count);
  for (unsigned int t = 0; t < loaded->triangle_count; ++t) {
    triangles[t] = {loaded->triangles[3 * t], loaded->triangles[3 * t + 1],
                    loaded->triangles[3 * t + 2]};
  }
  const std::string mesh_field = resource_field + " '" + resource + "'";
  const Eigen::Vector3d extent = high - low;
  for (unsigned int v = 0; v < loaded->vertex_count; ++v) {
    if (!unscaled[v].allFinite()) break;  // the file's: TriangleMesh::build names it
    for (int i = 0; i < 3; ++i) {
      if (std::isfinite(vertices[v][i])) continue;
      return core::Error{indexKey(scale_field, static_cast<std::size_t>(i)),
                         core::formatNumber(scale[i]) + " times the extent of '" + resource +
                             "' along its axis (" + core::formatNumber(extent[i]) +
                             " m at scale 1) overflows the doubles"};
    }
  }
  std::vector<std::size_t> zero_area;
  auto mesh = core::TriangleMesh::build(vertices, triangles, mesh_field, &zero_area);
  if (!mesh || !zero_area.empty()) {
    // The file's fault, or the scale's: the triangles at scale 1 tell.
    std::vector<std::size_t> zero_area_unscaled;
    const auto at_unit_scale =
        core::TriangleMesh::build(unscaled, triangles, mesh_field, &zero_area_unscaled);
    if (!at_unit_scale) return at_unit_scale.error();
    const std::size_t lost = vanished(zero_area, zero_area_unscaled);
    if (lost > 0) {
      return core::Error{
          scale_field,
          core::formatVector(scale) + " leaves " + std::to_string(lost) + " of the " +
              std::to_string(triangles.size() - zero_area_unscaled.size()) +
              " triangles of nonzero area of '" + resource +
              "' without area in doubles (their edges' squared lengths and cross products "
              "overflow or underflow): the mesh spans " +
              core::formatVector(extent) + " m at scale 1, " +
              core::formatVector(extent.cwiseProduct(scale)) + " m scaled"};
    }
    if (!mesh) return mesh.error();
  }
  if (!zero_area.empty()) {
    std::ostringstream list;
    const std::size_t shown = std::min<std::size_t>(zero_area.size(), 10);
    for (std::size_t i = 0; i < shown; ++i) list << (i ? ", " : "") << zero_area[i];
    if (shown < zero_area.size()) list << ", ... (" << zero_area.size() << " in all)";
    warnings.push_back(mesh_field + ": " + std::to_string(zero_area.size()) +
                       " triangle(s) of zero area left out (no face, no outside): " + list.str());
  }
  return mesh;
}

}  // namespace

core::Expected<std::shared_ptr<const core::TriangleMesh>> loadMeshResource(
    const std::string& resource, const Eigen::Vector3d& scale, const std::string& field,
    std::vector<std::string>& warnings, std::size_t max_bytes) {
  try {
    return loadWithinMemory(resource, scale, field, warnings, max_bytes);
  } catch (const std::bad_alloc&) {
    // Within max_mesh_bytes a file may still parse into more than this machine holds.
    return core::Error{joinKey(field, "resource"),
                       "'" + resource +
                           "' does not fit in memory once parsed (std::bad_alloc): a mesh of "
                           "fewer triangles, or a lower max_mesh_bytes to refuse such files "
                           "before they are read"};
  }
}

}  // namespace collision_response

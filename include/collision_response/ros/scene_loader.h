// The scene file (`~scene`, loaded from config/scenes/*.yaml by the launch file) -> core::Scene.
#pragma once

#include <XmlRpcValue.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/scene.h"

namespace collision_response {

/// The whole scene (keys in README.md, "Scene file"), validated (core::validateScene), its
/// planes' normals scaled to unit length. Every error names the parameter
/// (`field`/bodies[2]/mass) and the reason: an unknown key, a wrong type, a missing required
/// key, an unknown material, effect, detection or obstacle type, a duplicate name, a value out
/// of range.
///
/// A mesh obstacle's triangles are loaded from its `resource` (mesh_resource.h). With `robot:` the
/// links of the URDF that `urdf` returns for the parameter it names become obstacles
/// (robot_obstacles.h). What the scene leaves out (a mesh's zero-area triangles, a `<collision>`
/// without geometry), a body that starts inside a fixed obstacle (core::bodiesStartingInside) and
/// an obstacle placed beyond where its contacts resolve (core::obstaclesBeyondResolution) are
/// added to `warnings`, for the caller to log.
using UrdfSource = std::function<core::Expected<std::string>(const std::string& parameter)>;
core::Expected<core::Scene> loadScene(const XmlRpc::XmlRpcValue& scene, const std::string& field,
                                      const UrdfSource& urdf = nullptr,
                                      std::vector<std::string>* warnings = nullptr);

/// One entry of `bodies` (`field`: ".../bodies[2]"), its keys read into `body` by its `shape`'s
/// table (sphere by default), before any check across keys or of its mesh (loadScene loads a
/// mesh body's triangles from its `resource` and validates the scene).
core::Status readBody(const XmlRpc::XmlRpcValue& entry, const std::string& field,
                      core::BodySpec& body);

/// The URDF from the parameter server (a name relative to the node's namespace); an error names
/// `field`/robot/description.
UrdfSource parameterServerUrdf(const std::string& field);

/// The keys loadScene reads, by entity, as the README's tables name them: "scene", "bodies[]
/// sphere", "bodies[] box", "bodies[] cylinder, capsule", "bodies[] mesh",
/// "obstacles[] plane", "obstacles[] sphere", "obstacles[] box", "obstacles[] cylinder, capsule",
/// "obstacles[] mesh", "materials.<name>", "pairs[]", "robot". These are the key tables the loader
/// reads and checks with: a key is accepted exactly when it is listed here.
std::map<std::string, std::vector<std::string>> sceneKeys();

}  // namespace collision_response

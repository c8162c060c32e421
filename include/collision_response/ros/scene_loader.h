// The scene file (`~scene`, loaded from config/scenes/*.yaml by the launch file) -> core::Scene.
#pragma once

#include <XmlRpcValue.h>

#include <string>

#include "collision_response/core/expected.h"
#include "collision_response/core/materials.h"
#include "collision_response/core/scene.h"

namespace collision_response {

/// The material part of a scene: `restitution_combine`, `materials` and `pairs`, on top of the
/// seed's table. `scene` is the value of the `~scene` parameter; `field` its name for messages.
/// Unknown keys, unknown materials, duplicate names and out-of-range coefficients are errors.
core::Expected<core::MaterialTable> loadMaterials(const XmlRpc::XmlRpcValue& scene,
                                                  const std::string& field);

/// The whole scene (keys in README.md, "Scene file"), validated (core::validateScene). Every
/// error names the parameter (`field`/bodies[2]/mass) and the reason.
core::Expected<core::Scene> loadScene(const XmlRpc::XmlRpcValue& scene, const std::string& field);

}  // namespace collision_response

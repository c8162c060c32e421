#include "collision_response/ros/scene_loader.h"

#include <ros/names.h>
#include <ros/param.h>

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <utility>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/validation.h"
#include "collision_response/ros/mesh_resource.h"
#include "collision_response/ros/parameters.h"
#include "collision_response/ros/robot_obstacles.h"

namespace collision_response {
namespace {

using core::BodySpec;
using core::ObstacleSpec;
using core::Scene;

// One table per entity: the keys it may have, whether each is required, and how each is read
// and checked. readKeys refuses any key a table does not list, so a key is accepted exactly
// when it is read (README.md, "Scene file", documents each table; test_scene_loader.cpp checks
// the two agree).

const KeyTable<core::Material>& materialKeys() {
  static const KeyTable<core::Material> kKeys = {
      {"restitution", true,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, core::Material& material) {
         const auto number = readDouble(value, field);
         if (!number) return core::Status(number.error());
         if (auto status = core::checkRestitution(*number, field); !status) return status;
         material.restitution = *number;
         return core::Status(core::Ok{});
       }},
      {"friction", false,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, core::Material& material) {
         const auto number = readDouble(value, field);
         if (!number) return core::Status(number.error());
         if (auto status = core::checkFriction(*number, field); !status) return status;
         material.friction = *number;
         return core::Status(core::Ok{});
       }},
  };
  return kKeys;
}

/// A pair as read, before it joins the table (its materials must be known by then).
struct PairEntry {
  std::string first, second;
  core::PairCoefficients coefficients;
  const core::MaterialTable* materials = nullptr;
};

const KeyTable<PairEntry>& pairKeys() {
  static const KeyTable<PairEntry> kKeys = {
      {"materials", true,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, PairEntry& pair) {
         if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() != 2) {
           return core::Status(core::Error{field, "must be a list of two material names"});
         }
         for (int i = 0; i < 2; ++i) {
           const std::string item = indexKey(field, static_cast<std::size_t>(i));
           const auto name = readString(value[i], item);
           if (!name) return core::Status(name.error());
           if (auto status = pair.materials->checkMaterial(*name, item); !status) return status;
           (i == 0 ? pair.first : pair.second) = *name;
         }
         return core::Status(core::Ok{});
       }},
      {"restitution", true,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, PairEntry& pair) {
         const auto number = readDouble(value, field);
         if (!number) return core::Status(number.error());
         if (auto status = core::checkRestitution(*number, field); !status) return status;
         pair.coefficients.restitution = *number;
         return core::Status(core::Ok{});
       }},
      {"friction", false,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, PairEntry& pair) {
         const auto number = readDouble(value, field);
         if (!number) return core::Status(number.error());
         if (auto status = core::checkFriction(*number, field); !status) return status;
         pair.coefficients.friction = *number;
         return core::Status(core::Ok{});
       }},
  };
  return kKeys;
}

/// `inertia`: `solid` | `hollow`, or the tensor {ixx, iyy, izz, ixy, ixz, iyz} about the centre
/// of mass in the body's frame (kg m^2, URDF's names; the moments required, the products 0 by
/// default), checked by validateScene (core::checkBodyShape).
const KeyTable<core::InertiaTensor>& inertiaTensorKeys() {
  using core::InertiaTensor;
  static const KeyTable<InertiaTensor> kKeys = {
      numberKey<InertiaTensor>(
          "ixx", [](InertiaTensor& t) -> double& { return t.ixx; }, nullptr, true),
      numberKey<InertiaTensor>(
          "iyy", [](InertiaTensor& t) -> double& { return t.iyy; }, nullptr, true),
      numberKey<InertiaTensor>(
          "izz", [](InertiaTensor& t) -> double& { return t.izz; }, nullptr, true),
      numberKey<InertiaTensor>("ixy", [](InertiaTensor& t) -> double& { return t.ixy; }),
      numberKey<InertiaTensor>("ixz", [](InertiaTensor& t) -> double& { return t.ixz; }),
      numberKey<InertiaTensor>("iyz", [](InertiaTensor& t) -> double& { return t.iyz; }),
  };
  return kKeys;
}

core::Status readBodyInertia(const XmlRpc::XmlRpcValue& value, const std::string& field,
                             BodySpec& body) {
  if (value.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
    core::InertiaTensor tensor;
    if (auto status = readKeys(value, inertiaTensorKeys(), field, tensor); !status) return status;
    body.inertia_tensor = tensor;
    return core::Ok{};
  }
  const auto name = readString(value, field);
  if (!name) {
    return core::Error{field,
                       "must be `solid`, `hollow` or a tensor {ixx, iyy, izz, ixy, ixz, iyz}"};
  }
  const auto inertia = core::parseInertia(*name, field);
  if (!inertia) return inertia.error();
  body.inertia = *inertia;
  return core::Ok{};
}

/// `orientation: [x, y, z, w]`: a quaternion, not zero, normalised (an obstacle's shape's, a
/// body's).
template <class Spec>
core::Status readOrientation(const XmlRpc::XmlRpcValue& value, const std::string& field,
                             Spec& spec) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() != 4) {
    return core::Error{field, "must be a list of four numbers [x, y, z, w] (a quaternion)"};
  }
  double q[4];
  for (int i = 0; i < 4; ++i) {
    const auto component = readDouble(value[i], indexKey(field, static_cast<std::size_t>(i)));
    if (!component) return component.error();
    if (!std::isfinite(*component)) {
      return core::Error{indexKey(field, static_cast<std::size_t>(i)), "must be finite"};
    }
    q[i] = *component;
  }
  const Eigen::Quaterniond quaternion(q[3], q[0], q[1], q[2]);
  if (!(quaternion.norm() > 1e-6)) {
    return core::Error{field, "must not be zero (a rotation's quaternion has length 1)"};
  }
  spec.orientation = quaternion.normalized();
  return core::Ok{};
}

/// `rpy: [roll, pitch, yaw]` (rad, about the fixed x, y, z in that order, as URDF's).
template <class Spec>
core::Status readRollPitchYaw(const XmlRpc::XmlRpcValue& value, const std::string& field,
                              Spec& spec) {
  const auto angles = readVector3(value, field);
  if (!angles) return angles.error();
  if (auto status = core::checkFinite(*angles, field); !status) return status;
  spec.orientation = Eigen::AngleAxisd(angles->z(), Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(angles->y(), Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(angles->x(), Eigen::Vector3d::UnitX());
  return core::Ok{};
}

/// The keys every body has; `shape` was read first, to choose the table.
KeyTable<BodySpec> commonBodyKeys() {
  return {
      textKey<BodySpec>(
          "id", [](BodySpec& b) -> std::string& { return b.id; }, nullptr, true),
      {"shape", false,
       [](const XmlRpc::XmlRpcValue&, const std::string&, BodySpec&) {
         return core::Status(core::Ok{});  // read to choose this table
       }},
      numberKey<BodySpec>(
          "mass", [](BodySpec& b) -> double& { return b.mass; }, core::checkMass, true),
      textKey<BodySpec>(
          "material", [](BodySpec& b) -> std::string& { return b.material; }, nullptr, true),
      textKey<BodySpec>("topic", [](BodySpec& b) -> std::string& { return b.topic; }),
      vectorKey<BodySpec>("position", [](BodySpec& b) -> Eigen::Vector3d& { return b.position; }),
      vectorKey<BodySpec>("velocity", [](BodySpec& b) -> Eigen::Vector3d& { return b.velocity; }),
      vectorKey<BodySpec>("angular_velocity",
                          [](BodySpec& b) -> Eigen::Vector3d& { return b.angular_velocity; }),
      numberKey<BodySpec>("drag_coefficient",
                          [](BodySpec& b) -> double& { return b.drag_coefficient; }),
      numberKey<BodySpec>("lift_coefficient",
                          [](BodySpec& b) -> double& { return b.lift_coefficient; }),
      {"inertia", false, readBodyInertia},
      {"orientation", false, readOrientation<BodySpec>},
      {"rpy", false, readRollPitchYaw<BodySpec>},
  };
}

KeyTable<BodySpec> bodyKeysWith(const KeyTable<BodySpec>& shape_keys) {
  KeyTable<BodySpec> keys = commonBodyKeys();
  keys.insert(keys.end(), shape_keys.begin(), shape_keys.end());
  return keys;
}

const KeyTable<BodySpec>& sphereBodyKeys() {
  static const KeyTable<BodySpec> kKeys = bodyKeysWith({numberKey<BodySpec>(
      "radius", [](BodySpec& b) -> double& { return b.radius; }, core::checkRadius, true)});
  return kKeys;
}

const KeyTable<BodySpec>& boxBodyKeys() {
  static const KeyTable<BodySpec> kKeys = bodyKeysWith({vectorKey<BodySpec>(
      "size", [](BodySpec& b) -> Eigen::Vector3d& { return b.size; }, true)});
  return kKeys;
}

/// A cylinder's and a capsule's: radius and length along the body's z.
const KeyTable<BodySpec>& roundBodyKeys() {
  static const KeyTable<BodySpec> kKeys =
      bodyKeysWith({numberKey<BodySpec>(
                        "radius", [](BodySpec& b) -> double& { return b.radius; }, nullptr, true),
                    numberKey<BodySpec>(
                        "length", [](BodySpec& b) -> double& { return b.length; }, nullptr, true)});
  return kKeys;
}

/// A mesh body's (the convex hull of its vertices): its resource and scale, as an obstacle's.
const KeyTable<BodySpec>& meshBodyKeys() {
  static const KeyTable<BodySpec> kKeys = bodyKeysWith(
      {{"resource", true,
        [](const XmlRpc::XmlRpcValue& value, const std::string& field, BodySpec& body) {
          const auto text = readString(value, field);
          if (!text) return core::Status(text.error());
          body.resource = *text;
          return core::Status(core::Ok{});
        }},
       vectorKey<BodySpec>("scale", [](BodySpec& b) -> Eigen::Vector3d& { return b.scale; })});
  return kKeys;
}

const KeyTable<BodySpec>& bodyKeysOf(core::BodyShape shape) {
  switch (shape) {
    case core::BodyShape::kBox:
      return boxBodyKeys();
    case core::BodyShape::kCylinder:
    case core::BodyShape::kCapsule:
      return roundBodyKeys();
    case core::BodyShape::kMesh:
      return meshBodyKeys();
    case core::BodyShape::kSphere:
      break;
  }
  return sphereBodyKeys();
}

/// The keys every obstacle has; `type` was read first, to choose the table.
KeyTable<ObstacleSpec> commonObstacleKeys() {
  return {
      textKey<ObstacleSpec>(
          "id", [](ObstacleSpec& o) -> std::string& { return o.id; }, nullptr, true),
      {"type", true,
       [](const XmlRpc::XmlRpcValue&, const std::string&, ObstacleSpec&) {
         return core::Status(core::Ok{});  // read to choose this table
       }},
      textKey<ObstacleSpec>(
          "material", [](ObstacleSpec& o) -> std::string& { return o.material; }, nullptr, true),
      textKey<ObstacleSpec>("frame", [](ObstacleSpec& o) -> std::string& { return o.frame; }),
  };
}

const KeyTable<ObstacleSpec>& planeKeys() {
  static const KeyTable<ObstacleSpec> kKeys = [] {
    KeyTable<ObstacleSpec> keys = commonObstacleKeys();
    keys.push_back(vectorKey<ObstacleSpec>(
        "normal", [](ObstacleSpec& o) -> Eigen::Vector3d& { return o.normal; }, true));
    keys.push_back(
        numberKey<ObstacleSpec>("offset", [](ObstacleSpec& o) -> double& { return o.offset; }));
    return keys;
  }();
  return kKeys;
}

const KeyTable<ObstacleSpec>& sphereKeys() {
  static const KeyTable<ObstacleSpec> kKeys = [] {
    KeyTable<ObstacleSpec> keys = commonObstacleKeys();
    keys.push_back(numberKey<ObstacleSpec>(
        "radius", [](ObstacleSpec& o) -> double& { return o.radius; }, core::checkRadius, true));
    keys.push_back(vectorKey<ObstacleSpec>(
        "position", [](ObstacleSpec& o) -> Eigen::Vector3d& { return o.position; }));
    return keys;
  }();
  return kKeys;
}

/// The keys of a finite shape: where its centre is, how it is turned, and `size_keys`.
KeyTable<ObstacleSpec> finiteShapeKeys(const KeyTable<ObstacleSpec>& size_keys) {
  KeyTable<ObstacleSpec> keys = commonObstacleKeys();
  keys.push_back(vectorKey<ObstacleSpec>(
      "position", [](ObstacleSpec& o) -> Eigen::Vector3d& { return o.position; }));
  keys.push_back({"orientation", false, readOrientation<ObstacleSpec>});
  keys.push_back({"rpy", false, readRollPitchYaw<ObstacleSpec>});
  keys.insert(keys.end(), size_keys.begin(), size_keys.end());
  return keys;
}

const KeyTable<ObstacleSpec>& boxKeys() {
  static const KeyTable<ObstacleSpec> kKeys = finiteShapeKeys({vectorKey<ObstacleSpec>(
      "size", [](ObstacleSpec& o) -> Eigen::Vector3d& { return o.size; }, true)});
  return kKeys;
}

/// A mesh's: its resource (a package:// or file:// address) and its scale along its own axes.
const KeyTable<ObstacleSpec>& meshKeys() {
  static const KeyTable<ObstacleSpec> kKeys = finiteShapeKeys(
      {{"resource", true,
        [](const XmlRpc::XmlRpcValue& value, const std::string& field, ObstacleSpec& obstacle) {
          const auto text = readString(value, field);
          if (!text) return core::Status(text.error());
          obstacle.resource = *text;
          return core::Status(core::Ok{});
        }},
       vectorKey<ObstacleSpec>("scale",
                               [](ObstacleSpec& o) -> Eigen::Vector3d& { return o.scale; })});
  return kKeys;
}

/// A cylinder's and a capsule's: radius and length (along the shape's z).
const KeyTable<ObstacleSpec>& roundShapeKeys() {
  static const KeyTable<ObstacleSpec> kKeys = finiteShapeKeys(
      {numberKey<ObstacleSpec>(
           "radius", [](ObstacleSpec& o) -> double& { return o.radius; }, nullptr, true),
       numberKey<ObstacleSpec>(
           "length", [](ObstacleSpec& o) -> double& { return o.length; }, nullptr, true)});
  return kKeys;
}

core::Status readObstacle(const XmlRpc::XmlRpcValue& entry, const std::string& field,
                          ObstacleSpec& obstacle) {
  if (auto status = checkStruct(entry, field); !status) return status;
  if (!entry.hasMember("type")) return core::Error{joinKey(field, "type"), "is required"};
  const auto type = readString(entry["type"], joinKey(field, "type"));
  if (!type) return type.error();
  if (*type == "plane") {
    obstacle.shape = core::ObstacleShape::kPlane;
    return readKeys(entry, planeKeys(), field, obstacle);
  }
  if (*type == "sphere") {
    obstacle.shape = core::ObstacleShape::kSphere;
    return readKeys(entry, sphereKeys(), field, obstacle);
  }
  if (*type == "box" || *type == "cylinder" || *type == "capsule" || *type == "mesh") {
    if (entry.hasMember("orientation") && entry.hasMember("rpy")) {
      return core::Error{joinKey(field, "rpy"),
                         "give the orientation as `orientation` or as `rpy`, not both"};
    }
    obstacle.shape = *type == "box"        ? core::ObstacleShape::kBox
                     : *type == "cylinder" ? core::ObstacleShape::kCylinder
                     : *type == "capsule"  ? core::ObstacleShape::kCapsule
                                           : core::ObstacleShape::kMesh;
    return readKeys(entry,
                    *type == "box"    ? boxKeys()
                    : *type == "mesh" ? meshKeys()
                                      : roundShapeKeys(),
                    field, obstacle);
  }
  return core::Error{
      joinKey(field, "type"),
      "unknown obstacle type '" + *type + "'; known: plane, sphere, box, cylinder, capsule, mesh"};
}

/// A list whose every entry is read by `read_entry` into a new element of `list`.
template <class Entry, class ReadEntry>
core::Status readList(const XmlRpc::XmlRpcValue& value, const std::string& field,
                      std::vector<Entry>& list, ReadEntry read_entry) {
  if (auto status = checkArray(value, field); !status) return status;
  list.reserve(list.size() + static_cast<std::size_t>(value.size()));
  for (int i = 0; i < value.size(); ++i) {
    Entry entry;
    if (auto status = read_entry(value[i], indexKey(field, static_cast<std::size_t>(i)), entry);
        !status) {
      return status;
    }
    list.push_back(std::move(entry));
  }
  return core::Ok{};
}

const KeyTable<RobotLinks>& robotKeys() {
  static const KeyTable<RobotLinks> kKeys = {
      textKey<RobotLinks>(
          "description", [](RobotLinks& r) -> std::string& { return r.description; },
          [](const std::string& name, const std::string& field) -> core::Status {
            if (name.empty()) return core::Error{field, "must name a parameter"};
            return core::Ok{};
          }),
      {"links", false,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, RobotLinks& robot) {
         if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
           if (static_cast<std::string>(const_cast<XmlRpc::XmlRpcValue&>(value)) == "all") {
             robot.all_links = true;
             return core::Status(core::Ok{});
           }
           return core::Status(core::Error{field, "must be `all` or a list of link names"});
         }
         if (auto status = checkArray(value, field); !status) return status;
         if (value.size() == 0) return core::Status(core::Error{field, "names no link"});
         robot.all_links = false;
         for (int i = 0; i < value.size(); ++i) {
           const auto name = readString(value[i], indexKey(field, static_cast<std::size_t>(i)));
           if (!name) return core::Status(name.error());
           robot.links.push_back(*name);
         }
         return core::Status(core::Ok{});
       }},
      textKey<RobotLinks>(
          "material", [](RobotLinks& r) -> std::string& { return r.material; }, nullptr, true),
      numberKey<RobotLinks>(
          "padding", [](RobotLinks& r) -> double& { return r.padding; }, checkNonNegative),
  };
  return kKeys;
}

/// The scene's `max_mesh_bytes`: the largest mesh file read (mesh_resource.h), an integer >= 1.
core::Expected<std::size_t> readMaxMeshBytes(const XmlRpc::XmlRpcValue& value,
                                             const std::string& field) {
  const auto count = readInt(value, field);
  if (!count) return count.error();
  if (*count < 1) {
    return core::Error{field, "must be an integer >= 1 (bytes), got " + std::to_string(*count)};
  }
  return static_cast<std::size_t>(*count);
}

// The scene's keys that are more than a number, a text or a vector: each read into the scene.

core::Status readCombineRule(const XmlRpc::XmlRpcValue& value, const std::string& field,
                             Scene& scene) {
  const auto name = readString(value, field);
  if (!name) return core::Status(name.error());
  const auto rule = core::parseCombineRule(*name, field);
  if (!rule) return core::Status(rule.error());
  scene.materials.setCombineRule(*rule);
  return core::Status(core::Ok{});
}

core::Status readMaterials(const XmlRpc::XmlRpcValue& value, const std::string& field,
                           Scene& scene) {
  if (auto status = checkStruct(value, field); !status) return status;
  for (auto it = value.begin(); it != value.end(); ++it) {
    const std::string entry_field = joinKey(field, it->first);
    core::Material material;
    if (auto status = readKeys(it->second, materialKeys(), entry_field, material); !status) {
      return status;
    }
    if (auto status = scene.materials.addMaterial(it->first, material, entry_field); !status) {
      return status;
    }
  }
  return core::Status(core::Ok{});
}

core::Status readPairs(const XmlRpc::XmlRpcValue& value, const std::string& field, Scene& scene) {
  std::vector<PairEntry> pairs;
  return readList(
      value, field, pairs,
      [&scene](const XmlRpc::XmlRpcValue& entry, const std::string& entry_field, PairEntry& pair) {
        pair.materials = &scene.materials;
        if (auto status = readKeys(entry, pairKeys(), entry_field, pair); !status) {
          return status;
        }
        return scene.materials.addPair(pair.first, pair.second, pair.coefficients, entry_field);
      });
}

core::Status readDetection(const XmlRpc::XmlRpcValue& value, const std::string& field,
                           Scene& scene) {
  const auto name = readString(value, field);
  if (!name) return core::Status(name.error());
  const auto detection = core::parseDetection(*name, field);
  if (!detection) return core::Status(detection.error());
  scene.detection = *detection;
  return core::Status(core::Ok{});
}

core::Status readEffects(const XmlRpc::XmlRpcValue& value, const std::string& field, Scene& scene) {
  if (auto status = checkArray(value, field); !status) return status;
  for (int i = 0; i < value.size(); ++i) {
    const std::string item = indexKey(field, static_cast<std::size_t>(i));
    const auto name = readString(value[i], item);
    if (!name) return core::Status(name.error());
    if (auto status = core::addEffect(*name, item, scene.effects); !status) return status;
  }
  return core::Status(core::Ok{});
}

core::Status readBodies(const XmlRpc::XmlRpcValue& value, const std::string& field, Scene& scene) {
  return readList(value, field, scene.bodies, readBody);
}

core::Status readObstacles(const XmlRpc::XmlRpcValue& value, const std::string& field,
                           Scene& scene) {
  return readList(value, field, scene.obstacles, readObstacle);
}

/// Read by loadScene, once the other keys are: `robot` with the URDF it names, `max_mesh_bytes`
/// with the meshes it loads (the table's last keys, so that their errors come in its order).
core::Status readByLoadScene(const XmlRpc::XmlRpcValue&, const std::string&, Scene&) {
  return core::Status(core::Ok{});
}

const KeyTable<Scene>& sceneTable() {
  // The material keys first: bodies and pairs name materials.
  static const KeyTable<Scene> kKeys = {
      {"restitution_combine", false, readCombineRule},
      {"materials", false, readMaterials},
      {"pairs", false, readPairs},
      textKey<Scene>("fixed_frame", [](Scene& s) -> std::string& { return s.fixed_frame; }),
      {"detection", false, readDetection},
      {"effects", false, readEffects},
      vectorKey<Scene>("gravity", [](Scene& s) -> Eigen::Vector3d& { return s.gravity; }),
      numberKey<Scene>("restitution_threshold",
                       [](Scene& s) -> double& { return s.restitution_threshold; }),
      numberKey<Scene>("contact_integration_tolerance",
                       [](Scene& s) -> double& { return s.contact_integration_tolerance; }),
      numberKey<Scene>("air_density", [](Scene& s) -> double& { return s.air_density; }),
      numberKey<Scene>("flight_integration_tolerance",
                       [](Scene& s) -> double& { return s.flight_integration_tolerance; }),
      // Stepped clusters (README, "Scene file"): the time step's range is validateScene's.
      countKey<Scene>(
          "stepped_cluster_min_bodies",
          [](Scene& s) -> int& { return s.stepped_cluster_min_bodies; }, 0),
      numberKey<Scene>("stepped_cluster_time_step",
                       [](Scene& s) -> double& { return s.stepped_cluster_time_step; }),
      countKey<Scene>(
          "exact_work_budget", [](Scene& s) -> int& { return s.exact_work_budget; }, 0),
      {"bodies", false, readBodies},
      {"obstacles", false, readObstacles},
      {"robot", false, readByLoadScene},
      {"max_mesh_bytes", false, readByLoadScene},
  };
  return kKeys;
}

}  // namespace

core::Status readBody(const XmlRpc::XmlRpcValue& entry, const std::string& field,
                      core::BodySpec& body) {
  if (auto status = checkStruct(entry, field); !status) return status;
  if (entry.hasMember("shape")) {
    const std::string shape_field = joinKey(field, "shape");
    const auto name = readString(entry["shape"], shape_field);
    if (!name) return name.error();
    const auto shape = core::parseBodyShape(*name, shape_field);
    if (!shape) return shape.error();
    body.shape = *shape;
  }
  if (entry.hasMember("orientation") && entry.hasMember("rpy")) {
    return core::Error{joinKey(field, "rpy"),
                       "give the orientation as `orientation` or as `rpy`, not both"};
  }
  return readKeys(entry, bodyKeysOf(body.shape), field, body);
}

UrdfSource parameterServerUrdf(const std::string& field) {
  return [field](const std::string& parameter) -> core::Expected<std::string> {
    std::string xml;
    if (!ros::param::get(parameter, xml)) {
      return core::Error{joinKey(joinKey(field, "robot"), "description"),
                         "no string parameter '" + ros::names::resolve(parameter) +
                             "' (the robot's URDF, as robot_state_publisher reads it)"};
    }
    return xml;
  };
}

core::Expected<core::Scene> loadScene(const XmlRpc::XmlRpcValue& value, const std::string& field,
                                      const UrdfSource& urdf, std::vector<std::string>* warnings) {
  Scene scene;
  if (auto status = readKeys(value, sceneTable(), field, scene); !status) return status.error();
  // The meshes' triangles, from their resources, each file within the scene's limit.
  std::size_t max_mesh_bytes = kDefaultMaxMeshBytes;
  if (value.hasMember("max_mesh_bytes")) {
    const auto limit = readMaxMeshBytes(value["max_mesh_bytes"], joinKey(field, "max_mesh_bytes"));
    if (!limit) return limit.error();
    max_mesh_bytes = *limit;
  }
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    ObstacleSpec& obstacle = scene.obstacles[i];
    if (obstacle.shape != core::ObstacleShape::kMesh) continue;
    std::vector<std::string> left_out;
    auto triangles =
        loadMeshResource(obstacle.resource, obstacle.scale,
                         indexKey(joinKey(field, "obstacles"), i), left_out, max_mesh_bytes);
    if (!triangles) return triangles.error();
    obstacle.mesh = *triangles;
    if (warnings) warnings->insert(warnings->end(), left_out.begin(), left_out.end());
  }
  // A mesh body's triangles, the same way: the body is their convex hull.
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    BodySpec& body = scene.bodies[i];
    if (body.shape != core::BodyShape::kMesh) continue;
    std::vector<std::string> left_out;
    auto triangles = loadMeshResource(
        body.resource, body.scale, indexKey(joinKey(field, "bodies"), i), left_out, max_mesh_bytes);
    if (!triangles) return triangles.error();
    body.mesh = *triangles;
    if (warnings) warnings->insert(warnings->end(), left_out.begin(), left_out.end());
  }
  if (value.hasMember("robot")) {
    const std::string robot_field = joinKey(field, "robot");
    RobotLinks robot;
    robot.max_mesh_bytes = max_mesh_bytes;
    if (auto status = readKeys(value["robot"], robotKeys(), robot_field, robot); !status) {
      return status.error();
    }
    if (!urdf) {
      return core::Error{robot_field, "a robot's links need the parameter server's URDF"};
    }
    const auto xml = urdf(robot.description);
    if (!xml) return xml.error();
    std::vector<std::string> left_out;
    auto obstacles = robotObstacles(*xml, robot, robot_field, left_out);
    if (!obstacles) return obstacles.error();
    scene.obstacles.insert(scene.obstacles.end(), obstacles->begin(), obstacles->end());
    if (warnings) warnings->insert(warnings->end(), left_out.begin(), left_out.end());
  }
  if (auto status = core::validateScene(scene, field); !status) return status.error();
  core::normalizePlanes(scene);
  if (warnings) {
    const auto inside = core::bodiesStartingInside(scene);
    warnings->insert(warnings->end(), inside.begin(), inside.end());
    const auto coarse = core::obstaclesBeyondResolution(scene, field);
    warnings->insert(warnings->end(), coarse.begin(), coarse.end());
  }
  return scene;
}

std::map<std::string, std::vector<std::string>> sceneKeys() {
  return {{"scene", keyNames(sceneTable())},
          {"bodies[] sphere", keyNames(sphereBodyKeys())},
          {"bodies[] box", keyNames(boxBodyKeys())},
          {"bodies[] cylinder, capsule", keyNames(roundBodyKeys())},
          {"bodies[] mesh", keyNames(meshBodyKeys())},
          {"obstacles[] plane", keyNames(planeKeys())},
          {"obstacles[] sphere", keyNames(sphereKeys())},
          {"obstacles[] box", keyNames(boxKeys())},
          {"obstacles[] cylinder, capsule", keyNames(roundShapeKeys())},
          {"obstacles[] mesh", keyNames(meshKeys())},
          {"materials.<name>", keyNames(materialKeys())},
          {"pairs[]", keyNames(pairKeys())},
          {"robot", keyNames(robotKeys())}};
}

}  // namespace collision_response

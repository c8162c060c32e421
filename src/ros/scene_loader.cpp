#include "collision_response/ros/scene_loader.h"

#include "collision_response/ros/parameters.h"

namespace collision_response {
namespace {

// Every key a scene may have (DESIGN.md, "Scene").
const std::set<std::string> kSceneKeys = {
    "fixed_frame",         "detection", "effects", "gravity", "restitution_threshold",
    "restitution_combine", "materials", "pairs",   "bodies",  "obstacles"};

core::Expected<std::optional<double>> readOptionalDouble(const XmlRpc::XmlRpcValue& parent,
                                                         const std::string& key,
                                                         const std::string& field) {
  if (!parent.hasMember(key)) return std::optional<double>{};
  const auto value = readDouble(parent[key], joinKey(field, key));
  if (!value) return value.error();
  return std::optional<double>{*value};
}

core::Status loadMaterialEntries(const XmlRpc::XmlRpcValue& materials, const std::string& field,
                                 core::MaterialTable& table) {
  if (auto status = checkStruct(materials, field); !status) return status;
  for (auto it = materials.begin(); it != materials.end(); ++it) {
    const std::string entry_field = joinKey(field, it->first);
    if (auto status = checkKeys(it->second, {"restitution", "friction"}, entry_field); !status) {
      return status;
    }
    const auto restitution = readOptionalDouble(it->second, "restitution", entry_field);
    if (!restitution) return restitution.error();
    const auto friction = readOptionalDouble(it->second, "friction", entry_field);
    if (!friction) return friction.error();
    if (auto status =
            table.addMaterial(it->first, core::Material{*restitution, *friction}, entry_field);
        !status) {
      return status;
    }
  }
  return core::Ok{};
}

core::Status loadPairEntries(const XmlRpc::XmlRpcValue& pairs, const std::string& field,
                             core::MaterialTable& table) {
  if (auto status = checkArray(pairs, field); !status) return status;
  for (int i = 0; i < pairs.size(); ++i) {
    const std::string entry_field = indexKey(field, static_cast<std::size_t>(i));
    const XmlRpc::XmlRpcValue& entry = pairs[i];
    if (auto status = checkKeys(entry, {"materials", "restitution", "friction"}, entry_field);
        !status) {
      return status;
    }
    const std::string materials_field = joinKey(entry_field, "materials");
    if (!entry.hasMember("materials") ||
        entry["materials"].getType() != XmlRpc::XmlRpcValue::TypeArray ||
        entry["materials"].size() != 2) {
      return core::Error{materials_field, "must be a list of two material names"};
    }
    const auto first = readString(entry["materials"][0], indexKey(materials_field, 0));
    if (!first) return first.error();
    const auto second = readString(entry["materials"][1], indexKey(materials_field, 1));
    if (!second) return second.error();
    if (!entry.hasMember("restitution")) {
      return core::Error{joinKey(entry_field, "restitution"), "is required for a pair"};
    }
    const auto restitution = readDouble(entry["restitution"], joinKey(entry_field, "restitution"));
    if (!restitution) return restitution.error();
    const auto friction = readOptionalDouble(entry, "friction", entry_field);
    if (!friction) return friction.error();
    if (auto status = table.addPair(*first, *second,
                                    core::PairCoefficients{*restitution, *friction}, entry_field);
        !status) {
      return status;
    }
  }
  return core::Ok{};
}

core::Status readBodies(const XmlRpc::XmlRpcValue& list, const std::string& field,
                        core::Scene& scene) {
  if (auto status = checkArray(list, field); !status) return status;
  for (int i = 0; i < list.size(); ++i) {
    const std::string entry_field = indexKey(field, static_cast<std::size_t>(i));
    const XmlRpc::XmlRpcValue& entry = list[i];
    if (auto status =
            checkKeys(entry, {"id", "mass", "radius", "material", "topic", "position", "velocity"},
                      entry_field);
        !status) {
      return status;
    }
    core::BodySpec body;
    for (const char* required : {"id", "mass", "radius", "material"}) {
      if (!entry.hasMember(required)) {
        return core::Error{joinKey(entry_field, required), "is required"};
      }
    }
    auto id = readString(entry["id"], joinKey(entry_field, "id"));
    if (!id) return id.error();
    body.id = *id;
    auto mass = readDouble(entry["mass"], joinKey(entry_field, "mass"));
    if (!mass) return mass.error();
    body.mass = *mass;
    auto radius = readDouble(entry["radius"], joinKey(entry_field, "radius"));
    if (!radius) return radius.error();
    body.radius = *radius;
    auto material = readString(entry["material"], joinKey(entry_field, "material"));
    if (!material) return material.error();
    body.material = *material;
    if (entry.hasMember("topic")) {
      auto topic = readString(entry["topic"], joinKey(entry_field, "topic"));
      if (!topic) return topic.error();
      body.topic = *topic;
    }
    if (entry.hasMember("position")) {
      auto position = readVector3(entry["position"], joinKey(entry_field, "position"));
      if (!position) return position.error();
      body.position = *position;
    }
    if (entry.hasMember("velocity")) {
      auto velocity = readVector3(entry["velocity"], joinKey(entry_field, "velocity"));
      if (!velocity) return velocity.error();
      body.velocity = *velocity;
    }
    if (entry.hasMember("inertia")) {
      const std::string key = joinKey(entry_field, "inertia");
      auto name = readString(entry["inertia"], key);
      if (!name) return name.error();
      auto inertia = core::parseInertia(*name, key);
      if (!inertia) return inertia.error();
      body.inertia = *inertia;
    }
    scene.bodies.push_back(body);
  }
  return core::Ok{};
}

core::Status readObstacles(const XmlRpc::XmlRpcValue& list, const std::string& field,
                           core::Scene& scene) {
  if (auto status = checkArray(list, field); !status) return status;
  for (int i = 0; i < list.size(); ++i) {
    const std::string entry_field = indexKey(field, static_cast<std::size_t>(i));
    const XmlRpc::XmlRpcValue& entry = list[i];
    if (auto status = checkStruct(entry, entry_field); !status) return status;
    for (const char* required : {"id", "type", "material"}) {
      if (!entry.hasMember(required)) {
        return core::Error{joinKey(entry_field, required), "is required"};
      }
    }
    core::ObstacleSpec obstacle;
    auto type = readString(entry["type"], joinKey(entry_field, "type"));
    if (!type) return type.error();
    if (*type == "plane") {
      obstacle.shape = core::ObstacleShape::kPlane;
      if (auto status = checkKeys(entry, {"id", "type", "material", "frame", "normal", "offset"},
                                  entry_field);
          !status) {
        return status;
      }
      if (!entry.hasMember("normal")) {
        return core::Error{joinKey(entry_field, "normal"), "is required for a plane"};
      }
      auto normal = readVector3(entry["normal"], joinKey(entry_field, "normal"));
      if (!normal) return normal.error();
      obstacle.normal = *normal;
      if (entry.hasMember("offset")) {
        auto offset = readDouble(entry["offset"], joinKey(entry_field, "offset"));
        if (!offset) return offset.error();
        obstacle.offset = *offset;
      }
    } else if (*type == "sphere") {
      obstacle.shape = core::ObstacleShape::kSphere;
      if (auto status = checkKeys(entry, {"id", "type", "material", "frame", "position", "radius"},
                                  entry_field);
          !status) {
        return status;
      }
      if (!entry.hasMember("radius")) {
        return core::Error{joinKey(entry_field, "radius"), "is required for a sphere"};
      }
      auto radius = readDouble(entry["radius"], joinKey(entry_field, "radius"));
      if (!radius) return radius.error();
      obstacle.radius = *radius;
      if (entry.hasMember("position")) {
        auto position = readVector3(entry["position"], joinKey(entry_field, "position"));
        if (!position) return position.error();
        obstacle.position = *position;
      }
    } else {
      return core::Error{joinKey(entry_field, "type"),
                         "unknown obstacle type '" + *type + "'; known: plane, sphere"};
    }
    auto id = readString(entry["id"], joinKey(entry_field, "id"));
    if (!id) return id.error();
    obstacle.id = *id;
    auto material = readString(entry["material"], joinKey(entry_field, "material"));
    if (!material) return material.error();
    obstacle.material = *material;
    if (entry.hasMember("frame")) {
      auto frame = readString(entry["frame"], joinKey(entry_field, "frame"));
      if (!frame) return frame.error();
      obstacle.frame = *frame;
    }
    scene.obstacles.push_back(obstacle);
  }
  return core::Ok{};
}

}  // namespace

core::Expected<core::Scene> loadScene(const XmlRpc::XmlRpcValue& value, const std::string& field) {
  auto materials = loadMaterials(value, field);
  if (!materials) return materials.error();
  core::Scene scene;
  scene.materials = std::move(materials.value());
  if (value.hasMember("fixed_frame")) {
    auto frame = readString(value["fixed_frame"], joinKey(field, "fixed_frame"));
    if (!frame) return frame.error();
    scene.fixed_frame = *frame;
  }
  if (value.hasMember("detection")) {
    const std::string key = joinKey(field, "detection");
    auto name = readString(value["detection"], key);
    if (!name) return name.error();
    auto detection = core::parseDetection(*name, key);
    if (!detection) return detection.error();
    scene.detection = *detection;
  }
  if (value.hasMember("effects")) {
    const std::string key = joinKey(field, "effects");
    if (auto status = checkArray(value["effects"], key); !status) return status.error();
    for (int i = 0; i < value["effects"].size(); ++i) {
      const std::string item = indexKey(key, static_cast<std::size_t>(i));
      auto name = readString(value["effects"][i], item);
      if (!name) return name.error();
      if (auto status = core::addEffect(*name, item, scene.effects); !status) return status.error();
    }
  }
  if (value.hasMember("gravity")) {
    auto gravity = readVector3(value["gravity"], joinKey(field, "gravity"));
    if (!gravity) return gravity.error();
    scene.gravity = *gravity;
  }
  if (value.hasMember("restitution_threshold")) {
    auto threshold =
        readDouble(value["restitution_threshold"], joinKey(field, "restitution_threshold"));
    if (!threshold) return threshold.error();
    scene.restitution_threshold = *threshold;
  }
  if (value.hasMember("bodies")) {
    if (auto status = readBodies(value["bodies"], joinKey(field, "bodies"), scene); !status) {
      return status.error();
    }
  }
  if (value.hasMember("obstacles")) {
    if (auto status = readObstacles(value["obstacles"], joinKey(field, "obstacles"), scene);
        !status) {
      return status.error();
    }
  }
  if (auto status = core::validateScene(scene, field); !status) return status.error();
  return scene;
}

core::Expected<core::MaterialTable> loadMaterials(const XmlRpc::XmlRpcValue& scene,
                                                  const std::string& field) {
  if (auto status = checkKeys(scene, kSceneKeys, field); !status) return status.error();
  core::MaterialTable table = core::MaterialTable::seed();
  if (scene.hasMember("restitution_combine")) {
    const std::string rule_field = joinKey(field, "restitution_combine");
    const auto name = readString(scene["restitution_combine"], rule_field);
    if (!name) return name.error();
    const auto rule = core::parseCombineRule(*name, rule_field);
    if (!rule) return rule.error();
    table.setCombineRule(*rule);
  }
  if (scene.hasMember("materials")) {
    if (auto status = loadMaterialEntries(scene["materials"], joinKey(field, "materials"), table);
        !status) {
      return status.error();
    }
  }
  if (scene.hasMember("pairs")) {
    if (auto status = loadPairEntries(scene["pairs"], joinKey(field, "pairs"), table); !status) {
      return status.error();
    }
  }
  return table;
}

}  // namespace collision_response

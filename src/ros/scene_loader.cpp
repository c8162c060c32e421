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

}  // namespace

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

#include "collision_response/core/materials.h"

#include <algorithm>
#include <cmath>

#include "collision_response/core/validation.h"

namespace collision_response::core {

Expected<CombineRule> parseCombineRule(const std::string& name, const std::string& field) {
  if (name == "min") return CombineRule::kMin;
  if (name == "max") return CombineRule::kMax;
  if (name == "average") return CombineRule::kAverage;
  if (name == "multiply") return CombineRule::kMultiply;
  if (name == "geometric") return CombineRule::kGeometric;
  return Error{
      field, "unknown combine rule '" + name + "'; known: min, max, average, multiply, geometric"};
}

const char* toString(CombineRule rule) {
  switch (rule) {
    case CombineRule::kMin:
      return "min";
    case CombineRule::kMax:
      return "max";
    case CombineRule::kAverage:
      return "average";
    case CombineRule::kMultiply:
      return "multiply";
    case CombineRule::kGeometric:
      return "geometric";
  }
  return "unknown";
}

double combine(CombineRule rule, double x, double y) {
  switch (rule) {
    case CombineRule::kMin:
      return std::min(x, y);
    case CombineRule::kMax:
      return std::max(x, y);
    case CombineRule::kAverage:
      return 0.5 * (x + y);
    case CombineRule::kMultiply:
      return x * y;
    case CombineRule::kGeometric:
      return std::sqrt(x * y);
  }
  return std::min(x, y);
}

const std::vector<SeedMeasurement>& seedTable() {
  static const std::vector<SeedMeasurement> kTable = {
      {"range_golf_ball", "range golf ball", 0.858},
      {"tennis_ball", "tennis ball", 0.712},
      {"billiard_ball", "billiard ball", 0.804},
      {"hand_ball", "hand ball", 0.752},
      {"wooden_ball", "wooden ball", 0.603},
      {"steel_ball_bearing", "steel ball bearing", 0.597},
      {"glass_marble", "glass marble", 0.658},
      {"rubber_band_ball", "ball of rubber bands", 0.828},
      {"hollow_hard_plastic_ball", "hollow, hard plastic ball", 0.688},
  };
  return kTable;
}

MaterialTable MaterialTable::seed() {
  MaterialTable table;
  table.materials_[kReferenceSurface] = Material{};
  for (const SeedMeasurement& row : seedTable()) {
    // A seed material's own coefficient is its value against concrete.
    table.materials_[row.material] = Material{row.restitution, std::nullopt};
    table.pairs_[key(row.material, kReferenceSurface)] = PairCoefficients{row.restitution, {}};
  }
  return table;
}

Status MaterialTable::addMaterial(const std::string& name, const Material& material,
                                  const std::string& field) {
  if (auto status = checkName(name, field); !status) return status;
  if (contains(name)) {
    return Error{field, "material '" + name +
                            "' is already defined (built in or listed twice); to change a "
                            "measured pair, list it under pairs:"};
  }
  if (!material.restitution) {
    return Error{field + ".restitution", "is required (the material's own coefficient)"};
  }
  if (auto status = checkRestitution(*material.restitution, field + ".restitution"); !status) {
    return status;
  }
  if (material.friction) {
    if (auto status = checkFriction(*material.friction, field + ".friction"); !status) {
      return status;
    }
  }
  materials_[name] = material;
  return Ok{};
}

Status MaterialTable::addPair(const std::string& first, const std::string& second,
                              const PairCoefficients& coefficients, const std::string& field) {
  if (auto status = checkMaterial(first, field + ".materials[0]"); !status) return status;
  if (auto status = checkMaterial(second, field + ".materials[1]"); !status) return status;
  if (auto status = checkRestitution(coefficients.restitution, field + ".restitution"); !status) {
    return status;
  }
  if (coefficients.friction) {
    if (auto status = checkFriction(*coefficients.friction, field + ".friction"); !status) {
      return status;
    }
  }
  pairs_[key(first, second)] = coefficients;
  return Ok{};
}

std::vector<std::string> MaterialTable::names() const {
  std::vector<std::string> result;
  for (const auto& entry : materials_) result.push_back(entry.first);
  return result;
}

Expected<double> MaterialTable::restitution(const std::string& first, const std::string& second,
                                            const std::string& field_first,
                                            const std::string& field_second) const {
  if (auto status = checkMaterial(first, field_first); !status) return status.error();
  if (auto status = checkMaterial(second, field_second); !status) return status.error();
  if (const auto pair = pairs_.find(key(first, second)); pair != pairs_.end()) {
    return pair->second.restitution;
  }
  const std::optional<double>& own_first = materials_.at(first).restitution;
  const std::optional<double>& own_second = materials_.at(second).restitution;
  if (own_first && own_second) return combine(combine_rule_, *own_first, *own_second);
  if (own_first) return *own_first;  // second is the reference surface
  if (own_second) return *own_second;
  return Error{field_first + "/" + field_second,
               "no coefficient of restitution for '" + first + "' against '" + second +
                   "': neither is measured; list the pair under pairs:"};
}

Expected<double> MaterialTable::friction(const std::string& first, const std::string& second,
                                         const std::string& field_first,
                                         const std::string& field_second) const {
  if (auto status = checkMaterial(first, field_first); !status) return status.error();
  if (auto status = checkMaterial(second, field_second); !status) return status.error();
  if (const auto pair = pairs_.find(key(first, second));
      pair != pairs_.end() && pair->second.friction) {
    return *pair->second.friction;
  }
  const auto own = [this](const std::string& name) {
    return materials_.at(name).friction.value_or(kDefaultFriction);
  };
  if (first == kReferenceSurface && second == kReferenceSurface) return kDefaultFriction;
  if (second == kReferenceSurface) return own(first);
  if (first == kReferenceSurface) return own(second);
  return combine(combine_rule_, own(first), own(second));
}

std::vector<std::pair<std::string, double>> MaterialTable::againstReferenceSurface() const {
  std::vector<std::pair<std::string, double>> result;
  for (const auto& entry : materials_) {
    if (entry.first == kReferenceSurface) continue;
    const auto value = restitution(entry.first, kReferenceSurface);
    if (value) result.emplace_back(entry.first, *value);
  }
  return result;
}

MaterialTable::PairKey MaterialTable::key(const std::string& first, const std::string& second) {
  return first < second ? PairKey{first, second} : PairKey{second, first};
}

Status MaterialTable::checkMaterial(const std::string& name, const std::string& field) const {
  if (contains(name)) return Ok{};
  std::string known;
  for (const auto& entry : materials_) known += (known.empty() ? "" : ", ") + entry.first;
  return Error{field, "unknown material '" + name + "'; known: " + known};
}

}  // namespace collision_response::core

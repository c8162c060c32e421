// Materials and their coefficients: the seed's measured table, combine rules, explicit pairs.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "collision_response/core/expected.h"

namespace collision_response::core {

/// How two materials' own coefficients combine for a pair nobody measured.
enum class CombineRule { kMin, kMax, kAverage, kMultiply, kGeometric };

/// "min" | "max" | "average" | "multiply" | "geometric"; anything else is an error naming `field`.
Expected<CombineRule> parseCombineRule(const std::string& name, const std::string& field);
const char* toString(CombineRule rule);
/// min(x, y), max(x, y), (x + y) / 2, x y, or sqrt(x y).
double combine(CombineRule rule, double x, double y);

/// Coulomb friction coefficient of a material that names none (the seed measures restitution
/// only): 0.5, a middling value for a ball on a hard floor. Set `friction` to override it.
inline constexpr double kDefaultFriction = 0.5;

/// The name of the seed's reference surface: every measured coefficient is a ball against it.
inline constexpr const char* kReferenceSurface = "concrete";

/// A material's own coefficients. The own restitution of a ball material is its value against
/// the reference surface (the seed's table measures balls bounced on concrete); the reference
/// surface itself has none.
struct Material {
  std::optional<double> restitution;  ///< [0, 1]
  std::optional<double> friction;     ///< Coulomb mu, >= 0; used by the friction effect
};

/// Coefficients measured for one pair of materials.
struct PairCoefficients {
  double restitution = 0.0;        ///< [0, 1]
  std::optional<double> friction;  ///< >= 0
};

/// One row of the seed's table: a ball material bounced on concrete.
struct SeedMeasurement {
  const char* material;
  const char* description;  ///< as the slide names it
  double restitution;
};
/// The seed's "Coefficients of Restitution of Balls Bounced on a Concrete Surface".
const std::vector<SeedMeasurement>& seedTable();

/// Material names -> coefficients, with measured pairs taking precedence over the combine rule:
///   1. a pair in the table (seed or `pairs:`) uses its measured value, whatever the rule;
///   2. a material against the reference surface uses its own coefficient (that is what a
///      material's own coefficient means);
///   3. otherwise the combine rule joins the two own coefficients.
class MaterialTable {
 public:
  /// The seed's materials and pairs, combine rule `min`.
  static MaterialTable seed();

  /// Adds a material; an existing name, a bad name or an out-of-range coefficient is an error
  /// naming `field`.
  Status addMaterial(const std::string& name, const Material& material, const std::string& field);
  /// Adds (or replaces, for the seed's pairs) the measured coefficients of two known materials.
  Status addPair(const std::string& first, const std::string& second,
                 const PairCoefficients& coefficients, const std::string& field);
  void setCombineRule(CombineRule rule) { combine_rule_ = rule; }
  CombineRule combineRule() const { return combine_rule_; }

  bool contains(const std::string& name) const { return materials_.count(name) != 0; }
  /// Ok for a known material; otherwise the error naming `field`, with the known names: the
  /// one unknown-material message of the scene file and the service.
  Status checkMaterial(const std::string& name, const std::string& field) const;
  /// Every material name, sorted.
  std::vector<std::string> names() const;

  /// Coefficient of restitution of two materials; an unknown name is an error naming
  /// `field_first` or `field_second`.
  Expected<double> restitution(const std::string& first, const std::string& second,
                               const std::string& field_first = "first",
                               const std::string& field_second = "second") const;

  /// Coulomb friction coefficient of two materials, by the same rules as restitution: a pair's
  /// measured `friction`; a material against the reference surface: its own; otherwise the
  /// combine rule on the two own coefficients (kDefaultFriction where a material names none).
  Expected<double> friction(const std::string& first, const std::string& second,
                            const std::string& field_first = "first",
                            const std::string& field_second = "second") const;

  /// Each material with a coefficient against the reference surface, and that coefficient.
  std::vector<std::pair<std::string, double>> againstReferenceSurface() const;

 private:
  using PairKey = std::pair<std::string, std::string>;  // sorted
  static PairKey key(const std::string& first, const std::string& second);

  std::map<std::string, Material> materials_;
  std::map<PairKey, PairCoefficients> pairs_;
  CombineRule combine_rule_ = CombineRule::kMin;
};

}  // namespace collision_response::core

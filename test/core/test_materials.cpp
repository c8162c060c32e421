// Materials: the seed's pairs, combine rules for unmeasured pairs, explicit pair overrides.
#include <gtest/gtest.h>

#include <cmath>

#include "collision_response/core/materials.h"
#include "collision_response/core/restitution.h"

namespace collision_response::core {
namespace {

TEST(Materials, CombineRules) {
  EXPECT_EQ(combine(CombineRule::kMin, 0.6, 0.8), 0.6);
  EXPECT_EQ(combine(CombineRule::kMax, 0.6, 0.8), 0.8);
  EXPECT_EQ(combine(CombineRule::kAverage, 0.5, 0.75), 0.625);
  EXPECT_EQ(combine(CombineRule::kMultiply, 0.5, 0.75), 0.375);
  EXPECT_EQ(combine(CombineRule::kGeometric, 0.25, 0.64), 0.4);  // sqrt(0.16)
}

TEST(Materials, CombineRuleNames) {
  for (const CombineRule rule : {CombineRule::kMin, CombineRule::kMax, CombineRule::kAverage,
                                 CombineRule::kMultiply, CombineRule::kGeometric}) {
    const auto parsed = parseCombineRule(toString(rule), "restitution_combine");
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, rule);
  }
  const auto bad = parseCombineRule("median", "~scene/restitution_combine");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().field, "~scene/restitution_combine");
  EXPECT_NE(bad.error().reason.find("median"), std::string::npos);
}

// Two seed balls against each other were never measured: the rule combines their own values
// (each its value on concrete).
TEST(Materials, UnmeasuredPairUsesTheCombineRule) {
  MaterialTable table = MaterialTable::seed();
  EXPECT_EQ(*table.restitution("tennis_ball", "wooden_ball"), 0.603);  // min
  table.setCombineRule(CombineRule::kMax);
  EXPECT_EQ(*table.restitution("tennis_ball", "wooden_ball"), 0.712);
  table.setCombineRule(CombineRule::kAverage);
  EXPECT_EQ(*table.restitution("tennis_ball", "wooden_ball"), 0.5 * (0.712 + 0.603));
  table.setCombineRule(CombineRule::kMultiply);
  EXPECT_EQ(*table.restitution("tennis_ball", "wooden_ball"), 0.712 * 0.603);
  table.setCombineRule(CombineRule::kGeometric);
  EXPECT_EQ(*table.restitution("tennis_ball", "wooden_ball"), std::sqrt(0.712 * 0.603));
}

// A measured pair keeps its value under every rule.
TEST(Materials, MeasuredPairIgnoresTheCombineRule) {
  MaterialTable table = MaterialTable::seed();
  for (const CombineRule rule : {CombineRule::kMin, CombineRule::kMax, CombineRule::kAverage,
                                 CombineRule::kMultiply, CombineRule::kGeometric}) {
    table.setCombineRule(rule);
    EXPECT_EQ(*table.restitution("glass_marble", "concrete"), 0.658);
  }
}

TEST(Materials, ExplicitPairOverridesSeedAndRule) {
  MaterialTable table = MaterialTable::seed();
  ASSERT_TRUE(table.addMaterial("rubber", Material{0.85, 0.9}, "materials/rubber").ok());
  ASSERT_TRUE(
      table.addPair("rubber", "steel_ball_bearing", PairCoefficients{0.7, 0.4}, "pairs[0]").ok());
  EXPECT_EQ(*table.restitution("rubber", "steel_ball_bearing"), 0.7);
  EXPECT_EQ(*table.restitution("steel_ball_bearing", "rubber"), 0.7);
  // A user material's own coefficient is its value against the reference surface.
  EXPECT_EQ(*table.restitution("rubber", "concrete"), 0.85);
  // Unmeasured with a seed material: combined (min).
  EXPECT_EQ(*table.restitution("rubber", "tennis_ball"), 0.712);
  // Re-measuring a seed pair replaces it.
  ASSERT_TRUE(
      table.addPair("concrete", "tennis_ball", PairCoefficients{0.75, {}}, "pairs[1]").ok());
  EXPECT_EQ(*table.restitution("tennis_ball", "concrete"), 0.75);
}

TEST(Materials, Errors) {
  MaterialTable table = MaterialTable::seed();
  const auto unknown = table.restitution("tennis_ball", "unobtainium", "a.material", "b.material");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().field, "b.material");
  EXPECT_NE(unknown.error().reason.find("unobtainium"), std::string::npos);

  const auto concrete_pair = table.restitution("concrete", "concrete", "a.material", "b.material");
  ASSERT_FALSE(concrete_pair.ok()) << "concrete on concrete was never measured";

  EXPECT_EQ(table.addMaterial("tennis_ball", Material{0.5, {}}, "m").error().field, "m");
  EXPECT_EQ(table.addMaterial("gum", Material{}, "m/gum").error().field, "m/gum.restitution");
  EXPECT_EQ(table.addMaterial("gum", Material{1.5, {}}, "m/gum").error().field,
            "m/gum.restitution");
  EXPECT_EQ(table.addMaterial("gum", Material{0.5, -1.0}, "m/gum").error().field, "m/gum.friction");
  EXPECT_EQ(table.addMaterial("", Material{0.5, {}}, "m/").error().field, "m/");
  EXPECT_EQ(table.addPair("gum", "concrete", PairCoefficients{0.5, {}}, "pairs[0]").error().field,
            "pairs[0].materials[0]");
  EXPECT_EQ(table.addPair("concrete", "tennis_ball", PairCoefficients{-0.1, {}}, "pairs[0]")
                .error()
                .field,
            "pairs[0].restitution");
}

TEST(Materials, NearestMaterialOfTheTable) {
  const MaterialTable table = MaterialTable::seed();
  EXPECT_EQ(nearestMaterial(table, 0.712).name, "tennis_ball");
  EXPECT_EQ(nearestMaterial(table, 0.705).name,
            "tennis_ball");  // 0.007 from 0.712, 0.017 from 0.688
  EXPECT_EQ(nearestMaterial(table, 0.99).name, "range_golf_ball");
  EXPECT_EQ(nearestMaterial(table, 0.0).name, "steel_ball_bearing");
  EXPECT_EQ(nearestMaterial(table, 0.0).restitution, 0.597);
}

}  // namespace
}  // namespace collision_response::core

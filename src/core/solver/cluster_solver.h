// Everything a cluster of contacts receives at one instant: the joint normal solve, then the
// friction the scene's effects call for. The one place the service (computeCollision: a cluster
// of one contact) and the monitor (every cluster) resolve impacts.
#pragma once

#include <vector>

#include "collision_response/core/friction.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/simultaneous.h"
#include "solver/stepped_friction.h"

namespace collision_response::core {

/// The effects this build can run of `requested`: all of them in the product; none in the
/// benchmark's reference build, which links effect_selection_none.cpp instead of
/// effect_selection.cpp (scripts/bench_effects.sh counts instructions against it).
Effects runnableEffects(const Effects& requested);

/// Coulomb friction as the effects call for it, for one contact and for a cluster. Empty (no
/// friction effect): bodies slide freely. Chosen once, by frictionModelFor.
/// A cluster's friction step: every contact's tangential impulse, given its normal one, within
/// `work` (optional: solveFrictionImpulses).
using ClusterFrictionStep = void (*)(std::vector<ClusterBody>&, const std::vector<ClusterContact>&,
                                     const std::vector<FrictionContact>&,
                                     std::vector<FrictionOutcome>&, WorkBound* work);

struct FrictionModel {
  FrictionOutcome (*contact)(ClusterBody& a, ClusterBody& b, const ContactPoint& contact,
                             double friction, double normal_impulse) = nullptr;
  ClusterFrictionStep cluster = nullptr;
  /// A stepped cluster's sub-step: warm-started sweeps (applyFrictionBySweeps).
  SweptFrictionStep swept = nullptr;
  explicit operator bool() const { return contact != nullptr; }
};

/// Coulomb friction on every contact of a cluster at once (solveFrictionImpulses), its normal
/// impulses applied already: the tangential impulses come from one joint solve, as the normal
/// ones do, so mirror images get mirror answers and no order of the contacts matters. kSpin:
/// angular velocities enter the slip and receive the moments. The energy each contact removes
/// is the work of its impulse, -T.(u + u') / 2 (u, u' its slip before and after). `work`
/// (optional) bounds and counts the solve's work (solveFrictionImpulses).
template <bool kSpin>
void applyFrictionJointly(std::vector<ClusterBody>& bodies,
                          const std::vector<ClusterContact>& contacts,
                          const std::vector<FrictionContact>& frictions,
                          std::vector<FrictionOutcome>& outcomes, WorkBound* work = nullptr);

/// The friction `effects` call for: none (no friction effect), Coulomb friction on spheres that
/// do not turn, or (spin) on turning ones.
FrictionModel frictionModelFor(const Effects& effects);

/// What one contact received.
struct ContactResolution {
  ContactOutcome normal;
  FrictionOutcome friction;  ///< zero without a friction model
};

/// A cluster of one contact between `a` and `b`: resolveImpact (exact to the last bit), then the
/// model's friction with coefficient `friction`.
ContactResolution solveContact(ClusterBody& a, ClusterBody& b, const ClusterContact& contact,
                               double friction, const FrictionModel& friction_model);

struct ClusterOutcome {
  std::vector<ContactOutcome> normal;     ///< per contact
  std::vector<FrictionOutcome> friction;  ///< per contact; zero without a friction model
};

/// Resolves a cluster: the normal impulses of resolveSimultaneous, then the model's friction
/// with each contact's coefficient in `friction_coefficients` (read only with a model). The
/// bodies' velocities (and with spin their angular velocities) are updated. A cluster of one
/// contact is solveContact. `work` (optional) bounds and counts the joint solves' work
/// (resolveSimultaneous, then solveFrictionImpulses): where the normal solve runs out, the
/// bodies are left as they were and the outcome's `normal` is empty; where the friction's does,
/// its impulses are where it got to (within mu J, no energy added).
ClusterOutcome solveCluster(std::vector<ClusterBody>& bodies,
                            const std::vector<ClusterContact>& contacts,
                            const std::vector<double>& friction_coefficients,
                            const FrictionModel& friction_model, WorkBound* work = nullptr);

}  // namespace collision_response::core

// A dense cluster of bodies under gravity (a pile settling in a box) advanced by time steps
// instead of event by event. An exact event-driven model meets an inelastic collapse there (the
// impacts of a settling pile come ever closer: tens of thousands in one 10 ms update); a time
// step bounds the work and keeps every body outside every other. The monitor uses it for the
// clusters of near bodies the scene's `stepped_cluster_min_bodies` names (doc/model.md,
// "Lasting contact"); everything else stays exact.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <vector>

#include "collision_response/core/friction.h"
#include "collision_response/core/solver_body.h"
#include "solver/stepped_friction.h"

namespace collision_response::core {

/// A participant of a sub-step: a movable body, or (inverse mass 0) an obstacle or an immovable
/// body, which moves on at its velocity; its velocity is the one at the start, before `kick`.
struct SteppedBody : SolverBody {
  /// m/s: what gravity adds over the sub-step, g h (0 for an obstacle, or for a body given its
  /// gravity for this sub-step already).
  Eigen::Vector3d kick = Eigen::Vector3d::Zero();
};

/// A pair that may touch within the sub-step: two spheres, or a sphere and a plane.
/// Its normal and point are those at the start; the solve visits contacts in the order of their
/// points, so that no name or listing order of the bodies enters the answer.
struct SteppedContact : ContactPoint {
  double gap = 0.0;   ///< m at the start, surface to surface; < 0 overlapping (held, not pushed)
  double band = 0.0;  ///< m: within it the pair touches (it may strike); the overlap allowed
  double restitution = 0.0;
  double friction = 0.0;  ///< mu, read with a friction step only
  /// m/s: the speed at which the pair closed in the sub-step before, when it came into contact
  /// there (SteppedContactOutcome::arrival_speed); 0 when it did not. Its bounce is e times
  /// this, not e times what that sub-step's gap keeping left of it.
  double arrival_speed = 0.0;
  /// N s, on b: the friction impulse to start the friction sweeps from (the sub-step before's
  /// friction force times this one's duration); zero for none.
  Eigen::Vector3d friction_warm = Eigen::Vector3d::Zero();
};

struct SteppedSettings {
  double duration = 0.005;  ///< s, the sub-step h
  /// m/s: a touching contact approaching at least this fast bounces (restitution); slower ones
  /// only stop (the scene's restitution threshold).
  double restitution_threshold = 0.0;
  /// Coulomb friction on the contacts (FrictionModel::swept); null: frictionless.
  SweptFrictionStep friction = nullptr;
  /// Sweeps of the friction solve, at most.
  int max_friction_sweeps = 64;
  /// Iterations of each complementarity solve, at most.
  int max_iterations = 20000;
  /// Iterations of all the sub-step's complementarity solves and friction sweeps together, at
  /// most (a caller's work bound): past it a solve stops where it got to, not converged, and the
  /// sub-step ends early or is held (SteppedOutcome::duration, held).
  int max_total_iterations = std::numeric_limits<int>::max();
};

/// What a contact received over the sub-step.
struct SteppedContactOutcome {
  double approach_speed = 0.0;    ///< m/s at the start (> 0 closing)
  double bounce_impulse = 0.0;    ///< N s at the start: compression and restitution (an impact)
  double keeping_impulse = 0.0;   ///< N s keeping the gap: a force of impulse / duration
  double friction_impulse = 0.0;  ///< N s, tangential, on b along friction_direction
  Eigen::Vector3d friction_direction = Eigen::Vector3d::Zero();  ///< unit: the impulse's on b
  bool sticking = false;                                         ///< friction stopped the slip
  bool struck = false;  ///< touching and approaching at the threshold or faster
  /// m/s: not touching at the start, closed by the gap keeping within the sub-step: the speed
  /// it was closing at then (its bounce is the next sub-step's); 0 otherwise.
  double arrival_speed = 0.0;
};

struct SteppedOutcome {
  /// Per participant, over the sub-step: a straight line from the start at these velocities.
  std::vector<Eigen::Vector3d> velocity, angular_velocity;
  std::vector<SteppedContactOutcome> contacts;
  /// s: the sub-step's length, settings.duration, or shorter where a solve fell short of its
  /// tolerance: up to the first instant its velocities would close a contact (the caller solves
  /// again there).
  double duration = 0.0;
  bool converged = true;  ///< every solve reached its tolerance
  /// No solve gave velocities that keep the gaps even for an instant: every movable body is held
  /// still over the sub-step.
  bool held = false;
  int iterations = 0;       ///< of the complementarity solves, all together
  int friction_sweeps = 0;  ///< of the friction solve (applyFrictionBySweeps)
  /// The friction sweeps reached their tolerance (Coulomb's conditions to it); where not, the
  /// impulses are still within their bounds and add no energy.
  bool friction_converged = true;
};

/// One sub-step of a cluster (Stewart and Trinkle, "An implicit time-stepping scheme for rigid
/// body dynamics with inelastic collisions and Coulomb friction", 1996; Anitescu and Potra,
/// 1997), in four stages:
///
/// 1. Bounce: touching contacts (gap <= band) are compressed jointly (impulses J >= 0 after which
///    none approaches, J = 0 where one separates anyway); then those that struck (approaching, or
///    having arrived in the sub-step before, at the threshold or faster, and faster than a
///    bounce that would not leave the band) leave at e times that speed, the others do not
///    approach (Newton's law, jointly: impulses J >= 0 again). A restitution that would add
///    kinetic energy (contacts coupled through a light body), beyond what the sub-step before
///    took from the arrivals, is scaled down until it adds none.
/// 2. Gravity: every movable body's velocity gains its kick, g h.
/// 3. Gap keeping: the velocities nearest (in kinetic energy) to those, among the ones with
///    which every contact's gap at the sub-step's end, gap + d' h, is >= 0 (d' the normal
///    relative velocity; an overlap is held: d' >= 0). A sphere's distance is never less than
///    that linear gap along the start's normal, and the motion over the sub-step is a straight
///    line, so a pair that keeps it at both ends keeps it in between: no body goes into
///    another. This projection removes kinetic energy (its targets are <= 0).
/// 4. Friction (with a friction step): Coulomb's impulses on the contacts that carry a normal
///    impulse (mu times it their bound), by the warm-started sweeps of applyFrictionBySweeps in
///    the order of the contacts' points, to the solves' residual or `max_friction_sweeps`
///    (within their bounds and adding no energy either way); then stage 3 again, so that the
///    gaps hold whatever friction did.
///
/// The complementarity problems are solved by MPRGP (Dostal and Schoeberl, "Minimizing quadratic
/// functions subject to bound constraints with the rate of convergence and finite termination",
/// 2005: conjugate gradients with proportioning and gradient projections), with every sum in the
/// order of the contacts' points, to a residual of a quarter of the tightest contact's band per
/// sub-step. Where one does not get there within its iterations, the sub-step ends early, before
/// any contact would close past its band; where it cannot go on at all, every movable body is
/// held (`held`).
///
/// `warm`: the keeping impulses of a previous sub-step, per contact (N s), to start from; empty
/// for none. Contacts between two participants that do not move (inverse mass 0 both) are the
/// caller's error.
SteppedOutcome solveSteppedSubstep(const std::vector<SteppedBody>& bodies,
                                   const std::vector<SteppedContact>& contacts,
                                   const SteppedSettings& settings,
                                   const std::vector<double>& warm = {});

}  // namespace collision_response::core

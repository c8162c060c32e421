// Lasting contact: the forces with which bodies that rest, slide or roll on each other and on
// obstacles press on each other, and the accelerations those forces leave them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "collision_response/core/solver_body.h"

namespace collision_response::core {

/// A body of a contact group: a solver body (an obstacle or an immovable body has inverse mass 0,
/// and moves with constant velocity, acceleration 0) and its free accelerations.
struct ForceBody : SolverBody {
  /// m/s^2 without contact forces: gravity for a movable body, 0 for an immovable one.
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
  /// rad/s^2 without contact forces (0; see solveContactForces for its use with impulses).
  Eigen::Vector3d angular_acceleration = Eigen::Vector3d::Zero();
};

/// A touching pair of the group: b rests on a, or a on b (indices into the bodies).
struct ForceContact : ContactPoint {
  /// 1 / (distance between the centres) for two spheres, whose line of centres turns as they
  /// move; 0 against a plane; against a finite shape, 1 / (the centre's distance from the
  /// feature's core: an edge's line, a corner, a rim's circle; narrow_phase.h).
  double curvature = 0.0;
  /// Where the normal turns only across a direction (an edge, a cylinder's side, a rim): that
  /// direction (unit), along which it turns at `axial_share` of `curvature` (0 along a line);
  /// zero: it turns alike every way.
  Eigen::Vector3d turning_axis = Eigen::Vector3d::Zero();
  double axial_share = 1.0;
  double friction = 0.0;  ///< Coulomb mu; 0 frictionless (or no friction effect)
  /// For solveContactForcesWithModes: the direction a sliding contact slips in while its slip
  /// is below the slip tolerance (it starts to slide: the direction its mode was chosen with).
  /// Zero: its present slip's.
  Eigen::Vector3d slide_direction = Eigen::Vector3d::Zero();
};

/// How a contact carries its force.
enum class ContactMode {
  kSeparating,  ///< no force: the bodies move apart (or stay touching without pressing)
  kSliding,     ///< the surfaces slip: friction -mu N along the slip
  kSticking,    ///< no slip (resting, or rolling): static friction within mu N
};

struct ContactForce {
  ContactMode mode = ContactMode::kSeparating;
  double normal = 0.0;  ///< N, >= 0: on b along the normal, on a against it
  /// N, on b (on a the opposite), perpendicular to the normal: friction.
  Eigen::Vector3d tangential = Eigen::Vector3d::Zero();
  /// m/s: the slip, b's surface relative to a's at the contact point, perpendicular to the
  /// normal (0 while sticking).
  Eigen::Vector3d slip = Eigen::Vector3d::Zero();
  /// m/s^2: the slip's rate of change, and the gap's second derivative (>= 0; 0 where pressed).
  Eigen::Vector3d slip_acceleration = Eigen::Vector3d::Zero();
  double gap_acceleration = 0.0;
  /// Sliding: the unit direction of the slip friction acts against (for a contact that starts
  /// to slide, the direction of the slip it starts; zero otherwise).
  Eigen::Vector3d slide_direction = Eigen::Vector3d::Zero();
};

struct ContactForceSolution {
  std::vector<ContactForce> contacts;
  std::vector<Eigen::Vector3d> acceleration;          ///< per body, m/s^2
  std::vector<Eigen::Vector3d> angular_acceleration;  ///< per body, rad/s^2
  /// false: the modes did not settle within the iterations (the last ones are kept, clamped so
  /// that no contact pulls and no friction exceeds mu N).
  bool converged = true;
  /// The modes with friction did not settle, and the forces are those of the same group without
  /// friction (whose modes did): friction is lost here, rather than a contact left to close.
  bool friction_dropped = false;
};

/// Slower slips than this count as none (static friction): m/s.
struct ContactForceSettings {
  double slip_tolerance = 1e-9;
  int max_iterations = 64;
};

/// The contact forces of a group of touching bodies: every contact force is >= 0 and acts only
/// where the gap's acceleration is 0, and the gap's acceleration is >= 0 everywhere (Baraff,
/// "Fast contact force computation for nonpenetrating rigid bodies", SIGGRAPH 1994); with
/// friction, Coulomb's law: a sliding contact's friction is mu N against the slip, a sticking
/// one's is whatever keeps the slip at 0 as long as it is within mu N, and beyond it the contact
/// starts to slide.
///
/// For each assignment of modes (pressed or not; sticking or sliding) the conditions are linear
/// in the unknown forces: gap accelerations of pressed contacts 0, slip accelerations of sticking
/// ones 0. They are solved jointly (long double, minimum norm where contacts are redundant) and
/// the modes are changed where a condition fails (a pressed contact that would pull, a free one
/// that would close, a sticking one beyond mu N, a sliding one whose slip would reverse), all
/// failing contacts at once, until none fails. Nothing depends on the order of the bodies or
/// contacts.
///
/// The gap of two spheres accelerates by n.(a_b - a_a) + |v_perp|^2 / d (the line of centres
/// turns); the slip u = v_b - v_a - (r_a w_a + r_b w_b) x n changes at
/// a_b - a_a - (r_a al_a + r_b al_b) x n - (r_a w_a + r_b w_b) x n', n' = v_perp / d. A force F on
/// b at the contact (b's point is -r_b n from its centre) turns b at -(w_b / (k_b r_b)) n x F
/// (I = k m r^2), and a (its point r_a n, its force -F) at the same -(w_a / (k_a r_a)) n x F.
///
/// The same problem one level down is the inelastic impact of touching bodies: impulses J >= 0
/// with no contact approaching afterwards and J = 0 where it separates (friction stopping the
/// slip within mu J). Pass each body's velocities as its `acceleration` and
/// `angular_acceleration`, zero `velocity` and `angular_velocity`, curvature 0: the forces are
/// then the impulses, the accelerations the velocities after.
///
/// Where the modes with friction do not settle within `max_iterations` (seen for a stack of four
/// spinning balls with mu = 1 in a settling pile: the clamped forces left a contact's gap
/// accelerating inwards at 10.7 m/s^2), the group is solved again without friction and, if those
/// modes settle, that is the answer (`friction_dropped`): a body may slip where friction would
/// have held it, but no contact closes.
ContactForceSolution solveContactForces(const std::vector<ForceBody>& bodies,
                                        const std::vector<ForceContact>& contacts,
                                        const ContactForceSettings& settings = {});

/// The forces for modes given (each contact's: not pressed, sliding along its present slip, or
/// below the slip tolerance along its `slide_direction`, or sticking), without changing them: what
/// an integrator needs while the modes hold. The normal forces keep their sign (negative: the
/// contact would pull, so it lets go there).
ContactForceSolution solveContactForcesWithModes(const std::vector<ForceBody>& bodies,
                                                 const std::vector<ForceContact>& contacts,
                                                 const std::vector<ContactMode>& modes,
                                                 const ContactForceSettings& settings = {});
}  // namespace collision_response::core

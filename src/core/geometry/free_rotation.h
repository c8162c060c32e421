// A rigid body's rotation in flight, torque-free and exact (issue 42, build step 4): its angular
// velocity and orientation at any time from its principal moments, its first orientation and
// angular velocity. A shaped body's flight in the monitor, the scene player and its prediction
// (src/core/monitor/shaped_motion.h).
//
// In the body's principal frame Euler's equations J_1 w_1' = (J_2 - J_3) w_2 w_3 (cyclically)
// keep the kinetic energy E = (1/2) sum J_i w_i^2 and |L|^2 = M^2 = sum J_i^2 w_i^2, and L is
// fixed in the world. Solved in closed form (Landau and Lifshitz, Mechanics, sections 33 and 37):
// - isotropic (J_1 = J_2 = J_3): w constant, the body turns about it at |w|;
// - axisymmetric (two moments equal, J_t, and the symmetry axis s with J_s): the body-frame w
//   turns about s at lambda = (J_s - J_t) / J_t w_s, and R(t) = Rot(L, M t / J_t) R0
//   Rot(s, -lambda t) (regular precession);
// - asymmetric: with the middle moment J_2 and the axis the polhode goes round labelled 3 (the
//   largest when M^2 > 2 E J_2, the smallest when M^2 < 2 E J_2), w = (A_1 cn u, A_2 sn u,
//   A_3 dn u), u = omega t + u0, modulus m = (J_2 - J_1)(2 E J_3 - M^2) / ((J_3 - J_2)(M^2 - 2 E
//   J_1)), omega^2 = (J_3 - J_2)(M^2 - 2 E J_1) / (J_1 J_2 J_3) (Landau's (37.10) - (37.11)); on
//   the separatrix M^2 = 2 E J_2, sn = tanh, cn = dn = sech. The orientation is R(t) =
//   Rot(L, psi(t)) R0 D(l0) D(l(t))^T, D(l) the least rotation taking e_3 to l = J w / M (in
//   the body frame; l_3 keeps its sign, so D is smooth), and psi' = 2E / M - (l_1 l_2' -
//   l_2 l_1') / (1 + l_3) = 2E / M - (J_1 J_2 A_1 A_2 omega / M^2) dn u / (1 + a dn u), a =
//   J_3 A_3 / M: the angle about L is an elliptic integral of the third kind (van Zon and
//   Schofield, J. Comput. Phys. 225:145, 2007; Celledoni, Fasso, Safstrom and Zanna, SIAM J.
//   Sci. Comput. 30:2084, 2008, in another gauge). With phi = am u, its integral G(u) = integral
//   dphi / (1 + a Delta) is, times 1 - a^2, (T - a F) + a m / (3 (1 - a^2)) sin^3 phi R_J(cos^2
//   phi, Delta^2, 1, 1 - n sin^2 phi), n = -a^2 m / (1 - a^2), T = atan(sqrt(1 - n) tan phi) /
//   sqrt(1 - n) and F = sin phi R_F(cos^2 phi, Delta^2, 1) (Carlson's symmetric forms: Carlson,
//   Numer. Algorithms 10:13, 1995; DLMF 19.25.5, 19.25.14), over whole half periods of dn plus
//   the rest (|phi| <= pi / 2), so that it stays accurate over long times. Near a spin about
//   axis 3 (a -> 1) the bracket cancels, but the angle's factor over 1 - a^2, J_2 A_2 / (J_1 A_1),
//   stays bounded: psi keeps the doubles' rounding (test/core/test_free_rotation.cpp). Not by
//   stepping an ODE, nor by a quadrature per call.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

#include "collision_response/core/expected.h"

namespace collision_response::core {

/// sn, cn and dn of u for the parameter m = k^2, given m and m1 = 1 - m separately (near the
/// separatrix m1 is known to more digits than 1 - m). By the arithmetic-geometric mean
/// (Abramowitz and Stegun 16.4) after u is brought into [-2K, 2K]; dn = sqrt(m1 + m cn^2).
/// 0 <= m < 1, m1 > 0.
struct JacobiElliptic {
  double sn;
  double cn;
  double dn;
};
JacobiElliptic jacobiElliptic(double u, double m, double m1);

/// K(m) = R_F(0, m1, 1) (Carlson), m1 = 1 - m > 0.
double completeEllipticK(double m1);

/// F(phi | m), the amplitude phi in [-pi, pi] given by its sine and cosine: sin(phi) R_F(cos^2
/// phi, cos^2 phi + m1 sin^2 phi, 1) where cos(phi) >= 0, 2K - that beyond (Carlson, DLMF
/// 19.25.5), m1 = 1 - m > 0.
double ellipticF(double sine, double cosine, double m1);

/// A body's free rotation: the principal moments are about its body frame's x, y and z (any
/// order), `orientation` the body's at time 0 (world from body), `angular_velocity` its angular
/// velocity at time 0 in the world frame.
class FreeRotation {
 public:
  enum class Kind {
    kResting,       ///< w = 0
    kIsotropic,     ///< J_1 = J_2 = J_3, or a steady turn about a principal axis
    kAxisymmetric,  ///< two moments equal
    kAsymmetric,    ///< three different moments, M^2 != 2 E J_2
    kSeparatrix,    ///< three different moments, M^2 = 2 E J_2
  };

  /// Refuses, by name, moments that are not finite and > 0 ("principal_moments.x") or that
  /// break the triangle inequality, an orientation checkOrientation refuses ("orientation") and
  /// an angular velocity that is not finite ("angular_velocity.y") or whose angular momentum
  /// is beyond the doubles ("angular_velocity").
  static Expected<FreeRotation> create(const Eigen::Vector3d& principal_moments,
                                       const Eigen::Quaterniond& orientation,
                                       const Eigen::Vector3d& angular_velocity);

  Kind kind() const { return kind_; }
  /// The angular velocity at `time` in the body frame.
  Eigen::Vector3d bodyAngularVelocity(double time) const;
  /// The angular velocity at `time` in the world frame.
  Eigen::Vector3d angularVelocity(double time) const;
  /// The orientation at `time` (world from body).
  Eigen::Quaterniond orientation(double time) const;
  /// The period of the body-frame angular velocity: 2 pi / |lambda| (axisymmetric), 4 K(m) /
  /// |omega| (asymmetric: the intermediate axis's flip comes every half of it); infinite when
  /// it is constant or on the separatrix.
  double period() const;

 private:
  FreeRotation() = default;
  // create's stages once the input is checked and w, L and the kind's family are known.
  // Axisymmetric: lambda and M / J_t about the body axis `symmetry`.
  void startAxisymmetric(const Eigen::Vector3d& moments, int symmetry, int transverse);
  // Asymmetric: w scaled by a power of two, then each stage below, then R0 D(l0).
  void startAsymmetric(const Eigen::Vector3d& moments, const std::array<int, 3>& ascending);
  // The kind (either side of the separatrix or on it), the working frame and its moments, from
  // the scaled w `ws` and the axes in ascending order of their moments.
  void setWorkingFrame(const Eigen::Vector3d& moments, const Eigen::Vector3d& ws,
                       const std::array<int, 3>& ascending);
  // Where the elliptic motion starts in the working frame: (sn u0, cn u0) as a unit vector and
  // l0 = J w / M.
  struct WorkingStart {
    Eigen::Vector2d phase;
    Eigen::Vector3d momentum_direction;
  };
  // The amplitudes, omega, m, m1, a, the factor of G and 2E/M from the working frame's scaled
  // w `ww`, scaled back by 2^exponent.
  WorkingStart setEllipticMotion(const Eigen::Vector3d& ww, int exponent);
  // u0, K, the third kind's n, sqrt(1 - n) and factor, H(2K) and H(u0).
  void setPhase(const Eigen::Vector2d& phase);
  // w in the working frame at u = omega t + u0, given sn, cn and dn of u (unused on the
  // separatrix).
  Eigen::Vector3d workingAngularVelocity(double u, const JacobiElliptic& f) const;
  double psi(double time, const JacobiElliptic& f) const;
  // H(u) = (1 - a^2) G(u), G(u) = integral_0^u dn / (1 + a dn), given sn, cn and dn of u; within
  // a half period |v| <= K from sn v and cn v >= 0.
  double angleIntegral(double u, const JacobiElliptic& f) const;
  double angleIntegralWithin(double sine, double cosine) const;

  Kind kind_ = Kind::kResting;
  Eigen::Quaterniond orientation0_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d omega0_body_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d omega0_world_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d momentum_world_ = Eigen::Vector3d::Zero();  // L
  Eigen::Vector3d momentum_axis_ = Eigen::Vector3d::UnitZ();  // L / |L|
  // Axisymmetric: the symmetry axis (body frame), lambda and M / J_t.
  Eigen::Vector3d symmetry_axis_ = Eigen::Vector3d::UnitZ();
  double body_rate_ = 0.0;
  double precession_rate_ = 0.0;
  // Asymmetric: the working frame (rows: its axes in the body frame, det +1), its moments, the
  // amplitudes, omega, u0, m, m1, K, a, the factor of G, 2E/M, G(2K), G(u0) and R0 D(l0).
  Eigen::Matrix3d working_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d moments_ = Eigen::Vector3d::Ones();
  Eigen::Vector3d amplitude_ = Eigen::Vector3d::Zero();
  double rate_ = 0.0;
  double u0_ = 0.0;
  double m_ = 0.0;
  double m1_ = 1.0;
  double quarter_period_ = 0.0;  // K(m)
  double a_ = 0.0;
  double one_minus_a2_ = 1.0;     // 1 - a^2 = (J_1 A_1 / M)^2
  double characteristic_ = 0.0;   // n = -a^2 m / (1 - a^2)
  double root_ = 1.0;             // sqrt(1 - n)
  double rj_factor_ = 0.0;        // a m / (3 (1 - a^2))
  double psi_factor_ = 0.0;       // J_1 J_2 A_1 A_2 / (M^2 (1 - a^2)) = J_2 A_2 / (J_1 A_1)
  double energy_rate_ = 0.0;      // 2E / M
  double period_integral_ = 0.0;  // H(2K)
  double start_integral_ = 0.0;   // H(u0)
  Eigen::Quaterniond frame0_ = Eigen::Quaterniond::Identity();
};

}  // namespace collision_response::core

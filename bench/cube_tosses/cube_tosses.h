// The real cube tosses replayed by the peer engines (issue 42, step 8; scripts/cube_tosses.sh,
// doc/cube_tosses.md): 285 tosses of a 10.48 cm, 0.37 kg acrylic cube onto a table, tracked at
// 148 Hz (the ContactNets data set: Pfrommer, Halm and Posa, CoRL 2020), read where they are and
// never copied. Each peer is started from a toss's first recorded state and stepped at about
// 1 kHz (kStepsPerSample steps a sample), its pose taken at every sample's instant.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace collision_response::bench::cube_tosses {

using V = Eigen::Vector3d;
using Q = Eigen::Quaterniond;

/// The cube and the table, as the data set's README gives them.
constexpr double kWidth = 0.1048;      // m, the cube's side
constexpr double kHalfWidth = 0.0524;  // m
constexpr double kMass = 0.37;         // kg
/// kg m^2: the uniform solid cube's moment about any axis through its centre, m w^2 / 6.
constexpr double kInertia = kMass * kWidth * kWidth / 6.0;
constexpr double kTableTop = -0.001;   // m, z of the table's top in the data's frame
constexpr double kGravity = 9.81;      // m/s^2, along -z
constexpr double kSampleRate = 148.0;  // Hz, the recording's
/// The peers' step: 1/(148 x 7) s = 0.966 ms (1036 Hz, "1 kHz"), so that every sample's instant
/// ends a step and nothing is interpolated.
constexpr int kStepsPerSample = 7;
constexpr double kStep = 1.0 / (kSampleRate * kStepsPerSample);

/// The cube's pose: its centre (m, world) and its orientation (world from body).
struct Pose {
  V position = V::Zero();
  Q orientation = Q::Identity();
};

/// A toss's first state, in the data's conventions converted to the world frame.
struct State {
  Pose pose;
  V velocity = V::Zero();          ///< m/s, world
  V angular_velocity = V::Zero();  ///< rad/s, world (the data's body-frame rate turned)
};

/// The contact's parameters a peer is fitted by.
struct Contact {
  double restitution = 0.0;  ///< e (MuJoCo: its spring-dashpot's, spring_dashpot.h)
  double friction = 0.0;     ///< mu
};

/// Plays one toss from `first` for `samples` samples (the first one included) and returns the
/// pose at each sample's instant k / 148 s.
using Simulate = std::function<std::vector<Pose>(const State& first, std::size_t samples)>;

/// A peer engine: its name, how it is set (for the report), which parameters are fitted, and a
/// simulator for given contact parameters (made once per parameter pair: MuJoCo compiles a model).
struct Peer {
  std::string name;
  std::string setting;
  bool fits_restitution = true;  ///< false: e is not a parameter of this setting
  std::function<Simulate(const Contact&)> make;
};

#ifdef COLLISION_RESPONSE_WITH_BULLET
Peer bulletPeer();
#endif
#ifdef COLLISION_RESPONSE_WITH_ODE
Peer odePeer();
#endif
#ifdef COLLISION_RESPONSE_WITH_MUJOCO
/// `restitution`: e through a direct solref (spring_dashpot.h), fitted with mu; otherwise
/// MuJoCo's default soft contact, mu alone fitted.
Peer mujocoPeer(bool restitution);
#endif

}  // namespace collision_response::bench::cube_tosses

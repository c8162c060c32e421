// MuJoCo replays the cube tosses (only in the benchmark; the product never links MuJoCo): an MJCF
// model of a free box over a plane, timestep kStep, its default Euler integrator, Newton solver
// and pyramidal friction cone; the contact an explicit <pair> of condim 3 with friction mu.
// MuJoCo has no coefficient of restitution (its contacts are soft); its closest setting is the
// contact's spring and damper (solref), as in the literature's comparison on these tosses
// (Acosta, Yang and Posa, IEEE RA-L 2022). Two settings:
// - "e through solref": the direct solref (-stiffness, -damping) whose unilateral spring-dashpot
//   has restitution e (bench/accuracy/spring_dashpot.h), the contact's half period 8 steps and
//   solimp 0.9999 so that the contact follows that spring, as the accuracy benchmark sets it
//   (bench/accuracy/mujoco.cpp); e and mu fitted.
// - "default": MuJoCo's default soft contact (solref 0.02 1, solimp 0.9 0.95 0.001), mu fitted.
#include <mujoco/mujoco.h>

#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "cube_tosses.h"
#include "mujoco_model.h"
#include "spring_dashpot.h"

namespace collision_response::bench::cube_tosses {
namespace {

/// The contact's half period in steps (bench/accuracy/mujoco.cpp, kContactSteps).
constexpr double kContactSteps = 8.0;

std::string number(double value) { return mjcfNumber(value); }

std::string modelXml(const Contact& contact, bool restitution) {
  std::string solver;
  if (restitution) {
    const SpringDashpot spring = springDashpotFor(contact.restitution, kStep, kContactSteps);
    solver = " solref=\"" + number(-spring.stiffness) + " " + number(-spring.damping) +
             "\" solimp=\"0.9999 0.9999 0.001 0.5 2\"";
  }
  const std::string h = number(kHalfWidth);
  const std::string mu = number(contact.friction);
  return "<mujoco model=\"cube_toss\">\n  <option timestep=\"" + number(kStep) +
         "\" gravity=\"0 0 " + number(-kGravity) +
         "\"/>\n  <size nconmax=\"16\" njmax=\"64\"/>\n  <worldbody>\n"
         "    <geom name=\"table\" type=\"plane\" size=\"0 0 1\" pos=\"0 0 " +
         number(kTableTop) +
         "\" contype=\"0\" conaffinity=\"0\"/>\n"
         "    <body name=\"cube\"><freejoint/><geom name=\"cube\" type=\"box\" size=\"" +
         h + " " + h + " " + h + "\" mass=\"" + number(kMass) +
         "\"/></body>\n  </worldbody>\n  <contact>\n    <pair geom1=\"cube\" geom2=\"table\" "
         "condim=\"3\" friction=\"" +
         mu + " " + mu + " 0.005 0.0001 0.0001\"" + solver + "/>\n  </contact>\n</mujoco>\n";
}

std::vector<Pose> play(MujocoModel& compiled, const State& first, std::size_t samples) {
  const mjModel* m = compiled.model.get();
  mjData* d = compiled.data.get();
  mj_resetData(m, d);
  const V& p = first.pose.position;
  const Q& q = first.pose.orientation;
  const double qpos[7] = {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z()};
  std::memcpy(d->qpos, qpos, sizeof qpos);
  // A free joint's qvel: the linear velocity in the world frame, the angular one in the body's.
  const V w_body = q.conjugate() * first.angular_velocity;
  const double qvel[6] = {first.velocity.x(), first.velocity.y(), first.velocity.z(),
                          w_body.x(),         w_body.y(),         w_body.z()};
  std::memcpy(d->qvel, qvel, sizeof qvel);
  std::vector<Pose> path;
  path.reserve(samples);
  for (std::size_t k = 0; k < samples; ++k) {
    if (k > 0) {
      for (int s = 0; s < kStepsPerSample; ++s) mj_step(m, d);
    }
    path.push_back(Pose{V(d->qpos[0], d->qpos[1], d->qpos[2]),
                        Q(d->qpos[3], d->qpos[4], d->qpos[5], d->qpos[6]).normalized()});
  }
  if (d->warning[mjWARN_CONTACTFULL].number > 0 || d->warning[mjWARN_CNSTRFULL].number > 0) {
    throw std::runtime_error("MuJoCo: out of room for contacts (nconmax, njmax)");
  }
  return path;
}

}  // namespace

Peer mujocoPeer(bool restitution) {
  return Peer{restitution ? "MuJoCo, e through solref" : "MuJoCo, default contact",
              std::string("MuJoCo ") + mj_versionString() +
                  ": Euler, Newton solver, pyramidal cone, condim 3; " +
                  (restitution ? "direct solref for e (half period 8 steps), solimp 0.9999"
                               : "default solref 0.02 1, solimp 0.9 0.95 0.001 (e not a "
                                 "parameter)") +
                  "; 1036 Hz",
              restitution, [restitution](const Contact& contact) -> Simulate {
                auto compiled = compileMjcf(modelXml(contact, restitution), "cube_toss.xml");
                return [compiled](const State& first, std::size_t samples) {
                  return play(*compiled, first, samples);
                };
              }};
}

}  // namespace collision_response::bench::cube_tosses

// MuJoCo on the benchmark's scenes (only in the benchmark; the product never links MuJoCo).
//
// Each scene becomes an MJCF model: every ball a body with a free joint and a sphere geom of its
// mass, every obstacle a static plane or sphere geom; contacts frictionless (condim 1); one
// mj_step per state at the rate (timestep 1/rate; MuJoCo's default Euler integrator and Newton
// solver). Ball-obstacle contacts are explicit <pair>s (obstacles collide with nothing
// otherwise), so that each pair carries its own coefficient; ball-ball contacts are MuJoCo's
// own, with the balls' solref (the balls that meet in these scenes share one material).
//
// MuJoCo has no coefficient of restitution. Two settings:
// - default: MuJoCo's default soft contact (solref 0.02 1, solimp 0.9 0.95 0.001: a critically
//   damped contact, which does not bounce by design).
// - restitution: the bounce its documentation prescribes (modeling guide, "Restitution": "When
//   both numbers [of solref] are non-positive, they are interpreted as (-stiffness, -damping) ...
//   To achieve perfect restitution ... set stiffness to some reasonably large value and damping
//   to zero"), with the damping for e < 1 from the linear spring-dashpot contact that MuJoCo's
//   reference acceleration a_ref = -b v - k r describes (computation chapter, "Solver
//   parameters"): a unilateral spring-dashpot's coefficient (spring_dashpot.h). The naive e =
//   exp(-pi beta / w) of a bilateral oscillator is what gives the e = 0.75 -> 0.82 users report.
//   The stiffness: a contact's half period pi / sqrt(k) spans kContactSteps steps (MuJoCo's own
//   guidance is a time constant of at least two steps, XML reference, solref); solimp 0.9999 0.9999
//   (mjMAXIMP) so that the contact follows a_ref (the impedance d blends a_ref with the
//   unconstrained acceleration, a = d a_ref + (1 - d) a0).
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>

#include "harness.h"
#include "mujoco_model.h"
#include "spring_dashpot.h"

namespace collision_response::bench {
namespace {

/// A contact lasts this many steps (its half period): the best of 2, 4, 8 and 16 over the drop
/// test, the cradle, the break and the gas at 10 to 1000 Hz (2 and 4: the spring is integrated
/// too coarsely, energy drifts by tens of percent; 16: gravity acts over a long contact and
/// touching contacts blur more). Stiffer or softer, MuJoCo's bounce is off by several percent:
/// the contact is soft, and gravity pulls during it.
constexpr double kContactSteps = 8.0;

std::string number(double value) { return mjcfNumber(value); }
std::string triple(const V& v) { return number(v.x()) + " " + number(v.y()) + " " + number(v.z()); }

/// solref and solimp attributes giving `restitution` at time step dt; empty: MuJoCo's defaults.
std::string contactAttributes(bool restitution_on, double restitution, double dt) {
  if (!restitution_on) return "";
  // Half period kContactSteps steps.
  const SpringDashpot contact = springDashpotFor(restitution, dt, kContactSteps);
  return " solref=\"" + number(-contact.stiffness) + " " + number(-contact.damping) +
         "\" solimp=\"0.9999 0.9999 0.001 0.5 2\"";
}

std::string modelXml(const core::Scene& scene, double dt, bool restitution_on) {
  const V g = scene.effects.gravity ? scene.gravity : V::Zero();
  // Room for four contacts per ball at once (one constraint row each, condim 1): MuJoCo 2.2
  // preallocates dense njmax x njmax matrices, so not more; an overflow is reported (truncated).
  const std::string contacts = std::to_string(std::max<std::size_t>(32, 4 * scene.bodies.size()));
  std::string xml = "<mujoco model=\"bench\">\n  <option timestep=\"" + number(dt) +
                    "\" gravity=\"" + triple(g) + "\"/>\n  <size nconmax=\"" + contacts +
                    "\" njmax=\"" + contacts + "\"/>\n";
  xml += "  <default><geom condim=\"1\"/><pair condim=\"1\"/></default>\n  <worldbody>\n";
  for (std::size_t o = 0; o < scene.obstacles.size(); ++o) {
    const core::ObstacleSpec& spec = scene.obstacles[o];
    if (spec.shape == core::ObstacleShape::kPlane) {
      const V n = spec.normal.normalized();
      xml += "    <geom name=\"o" + std::to_string(o) + "\" type=\"plane\" size=\"0 0 1\" pos=\"" +
             triple(n * spec.offset) + "\" zaxis=\"" + triple(n) +
             "\" contype=\"0\" conaffinity=\"0\"/>\n";
    } else if (spec.shape == core::ObstacleShape::kBox) {  // along the axes
      xml += "    <geom name=\"o" + std::to_string(o) + "\" type=\"box\" size=\"" +
             triple(0.5 * spec.size) + "\" pos=\"" + triple(spec.position) +
             "\" contype=\"0\" conaffinity=\"0\"/>\n";
    } else {
      xml += "    <geom name=\"o" + std::to_string(o) + "\" type=\"sphere\" size=\"" +
             number(spec.radius) + "\" pos=\"" + triple(spec.position) +
             "\" contype=\"0\" conaffinity=\"0\"/>\n";
    }
  }
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const core::BodySpec& spec = scene.bodies[i];
    const double e_ball = *scene.materials.restitution(spec.material, spec.material);
    xml += "    <body name=\"b" + std::to_string(i) + "\" pos=\"" + triple(spec.position) +
           "\"><freejoint/><geom name=\"b" + std::to_string(i) + "\" type=\"sphere\" size=\"" +
           number(spec.radius) + "\" mass=\"" + number(spec.mass) + "\"" +
           contactAttributes(restitution_on, e_ball, dt) + "/></body>\n";
  }
  xml += "  </worldbody>\n  <contact>\n";
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    for (std::size_t o = 0; o < scene.obstacles.size(); ++o) {
      const double e =
          *scene.materials.restitution(scene.bodies[i].material, scene.obstacles[o].material);
      xml += "    <pair geom1=\"b" + std::to_string(i) + "\" geom2=\"o" + std::to_string(o) + "\"" +
             contactAttributes(restitution_on, e, dt) + "/>\n";
    }
  }
  return xml + "  </contact>\n</mujoco>\n";
}

}  // namespace

Engine mujocoEngine(bool restitution) {
  // Compiling a model (parsing the MJCF) is done once per scene and rate, outside the runs that
  // are timed: a user compiles once and steps many times.
  auto models = std::make_shared<std::map<std::string, std::shared_ptr<MujocoModel>>>();
  return [restitution, models](const core::Scene& scene, const Play& play) {
    if (movesObstacles(play)) {
      Run run;
      run.unsupported = "no moving obstacles in this harness";
      return run;
    }
    if (hasMesh(scene)) {
      Run run;
      run.unsupported = "no triangle meshes in this harness (MuJoCo collides a mesh's convex hull)";
      return run;
    }
    const double dt = 1.0 / play.rate;
    const std::string xml = modelXml(scene, dt, restitution);
    auto found = models->find(xml);
    if (found == models->end()) found = models->emplace(xml, compileMjcf(xml, "scene.xml")).first;
    const mjModel* m = found->second->model.get();
    mjData* d = found->second->data.get();
    mj_resetData(m, d);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      // A free joint's qvel: linear velocity in the world frame, then angular.
      for (int k = 0; k < 3; ++k)
        d->qvel[6 * i + static_cast<std::size_t>(k)] = scene.bodies[i].velocity[k];
    }
    Run run;
    const auto updates = static_cast<long>(std::llround(play.duration * play.rate));
    std::vector<V> positions(scene.bodies.size()), velocities(scene.bodies.size());
    for (long k = 0; k <= updates; ++k) {
      if (k > 0) mj_step(m, d);
      for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        positions[i] = V(d->qpos[7 * i], d->qpos[7 * i + 1], d->qpos[7 * i + 2]);
        velocities[i] = V(d->qvel[6 * i], d->qvel[6 * i + 1], d->qvel[6 * i + 2]);
      }
      run.record(play, static_cast<double>(k) * dt, positions, velocities);
    }
    run.truncated =
        d->warning[mjWARN_CONTACTFULL].number > 0 || d->warning[mjWARN_CNSTRFULL].number > 0;
    return run;
  };
}

}  // namespace collision_response::bench

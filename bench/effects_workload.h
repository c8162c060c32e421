// The workloads of the effects benchmarks, shared by the timing (bench_effects.cpp) and the
// instruction count (effects_instructions.cpp).
#pragma once

#include <random>
#include <string>
#include <vector>

#include "box_walls.h"
#include "collision_response/core/collision.h"
#include "collision_response/core/monitor.h"

namespace collision_response::bench {

using V = Eigen::Vector3d;

/// One ball striking the floor obliquely with spin, through the service's core path.
inline core::CollisionRequest ballOnFloor(const std::vector<std::string>& effects) {
  core::CollisionRequest request;
  request.a.mass = 0.057;
  request.a.radius = 0.033;
  request.a.velocity = V(3, 0, -4);
  request.a.angular_velocity = V(0, 20, 0);
  request.b.mass = core::kImmovableMass;
  request.normal = V(0, 0, -1);
  request.restitution = 0.7;
  request.friction = effects.empty() ? 0.0 : 0.5;
  request.effects = effects;
  return request;
}

/// 100 balls in a closed 2 m box, random velocities, the given effects.
inline core::Scene boxScene(bool gravity, bool friction, bool spin, bool drag, bool magnus) {
  core::Scene scene;
  scene.effects.gravity = gravity;
  scene.effects.friction = friction;
  scene.effects.spin = spin;
  scene.effects.drag = drag;
  scene.effects.magnus = magnus;
  const double size = 2.0;
  addBoxWalls(scene, size, "billiard_ball");
  for (int i = 0; i < 100; ++i) {
    core::BodySpec body;
    body.id = "ball_" + std::to_string(1000 + i);
    body.mass = 0.17;
    body.radius = 0.05;
    body.material = "billiard_ball";
    body.position = V(0.1 + 0.2 * (i % 10), 0.1 + 0.2 * ((i / 10) % 10), 1.0);
    scene.bodies.push_back(body);
  }
  return scene;
}

/// The monitor on the box, fed at 100 Hz with every body's state: its own predicted state, as a
/// source that applies the responses publishes them.
class BoxRun {
 public:
  BoxRun(bool gravity, bool friction, bool spin, bool drag = false, bool magnus = false)
      : scene_(boxScene(gravity, friction, spin, drag, magnus)),
        monitor_(scene_, core::MonitorSettings{}) {
    std::mt19937_64 engine(1);
    std::uniform_real_distribution<double> speed(-2.0, 2.0);
    states_.resize(scene_.bodies.size());
    for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
      states_[i].body = *monitor_.bodyIndex(scene_.bodies[i].id);
      states_[i].position = scene_.bodies[i].position;
      states_[i].velocity = V(speed(engine), speed(engine), speed(engine));
      states_[i].angular_velocity = V(speed(engine), speed(engine), speed(engine));
    }
    monitor_.step(0.0, states_);
  }

  /// One state update; returns the impacts it found.
  std::size_t update() {
    time_ += 0.01;
    for (core::BodyStateSample& sample : states_) {
      const auto predicted = monitor_.predictedState(sample.body, time_);
      sample.time = time_;
      sample.position = predicted->first;
      sample.velocity = predicted->second;
      sample.angular_velocity = monitor_.predictedAngularVelocity(sample.body, time_);
    }
    return monitor_.step(time_, states_).impacts.size();
  }

 private:
  core::Scene scene_;
  core::ImpactMonitor monitor_;
  std::vector<core::BodyStateSample> states_;
  double time_ = 0.0;
};

}  // namespace collision_response::bench

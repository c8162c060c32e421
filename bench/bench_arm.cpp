// A ball against a seven-joint arm (urdf/seven_link_arm.urdf, its obstacles made by the scene's
// `robot:` code from the URDF) whose joints turn at constant speeds, at 1 kHz: each update asks
// for the first contact of the ball with any of the seven links within the update, from the
// links' poses at its start (ours: with each link's linear and angular velocity, as tf gives
// them) or at its start and end (Bullet's btContinuousConvexCollision with convex shapes, FCL's
// continuousCollide: its defaults, and with screw motion). Side by side: CPU per update (seven
// queries), and each engine's time of impact against the exact instant along the arm's true
// motion (its forward kinematics), found by conservative advancement in long double on the
// distance to each link by its own formula. 256 throws: balls of r 0.03 m thrown at 2 to 4 m/s
// from about 1 m at points within the arm's reach, the joints turning at up to 2 rad/s.
//   cmake --build .ws/build --target bench_arm && .ws/devel/lib/collision_response/bench_arm
#include <benchmark/benchmark.h>
#include <urdf/model.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "collision_response/ros/robot_obstacles.h"
#include "geometry/narrow_phase.h"

#ifdef COLLISION_RESPONSE_WITH_BULLET
#include <BulletCollision/NarrowPhaseCollision/btContinuousConvexCollision.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <btBulletCollisionCommon.h>
#endif
#ifdef COLLISION_RESPONSE_WITH_FCL
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/continuous_collision.h>
#endif

namespace {

using namespace collision_response;
using V = Eigen::Vector3d;
using LD = long double;
constexpr double kRate = 1000.0, kStep = 1.0 / kRate, kRadius = 0.03;
constexpr int kThrows = 256;

/// The arm's chain: each joint's origin in its parent link and its axis; the obstacles.
struct Arm {
  std::vector<Eigen::Isometry3d> origins;
  std::vector<V> axes;
  std::vector<core::ObstacleSpec> obstacles;  // one a link, in chain order
};

Arm loadArm() {
  std::ifstream file(COLLISION_RESPONSE_ARM_URDF);
  std::stringstream text;
  text << file.rdbuf();
  const std::string xml = text.str();
  urdf::Model model;
  if (!model.initString(xml)) throw std::runtime_error("the arm's URDF does not parse");
  RobotLinks robot;
  robot.material = "concrete";
  std::vector<std::string> warnings;
  const auto obstacles = robotObstacles(xml, robot, "arm", warnings);
  if (!obstacles) throw std::runtime_error(obstacles.error().message());
  Arm arm;
  for (int i = 1; i <= 7; ++i) {
    const auto joint = model.getJoint("joint" + std::to_string(i));
    const urdf::Pose& origin = joint->parent_to_joint_origin_transform;
    Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
    transform.translation() = V(origin.position.x, origin.position.y, origin.position.z);
    double x = 0, y = 0, z = 0, w = 1;
    origin.rotation.getQuaternion(x, y, z, w);
    transform.linear() = Eigen::Quaterniond(w, x, y, z).toRotationMatrix();
    arm.origins.push_back(transform);
    arm.axes.emplace_back(joint->axis.x, joint->axis.y, joint->axis.z);
    for (const core::ObstacleSpec& spec : *obstacles) {
      if (spec.frame == "link" + std::to_string(i)) arm.obstacles.push_back(spec);
    }
  }
  return arm;
}

/// Each link's frame at joint angles q turning at qd: its pose, its origin's velocity and its
/// angular velocity (forward kinematics, in Scalar).
template <class Scalar>
struct LinkPose {
  Eigen::Transform<Scalar, 3, Eigen::Isometry> transform;
  Eigen::Matrix<Scalar, 3, 1> velocity, angular;
};
template <class Scalar>
std::vector<LinkPose<Scalar>> kinematics(const Arm& arm, const std::vector<double>& q0,
                                         const std::vector<double>& qd, Scalar t) {
  using Vec = Eigen::Matrix<Scalar, 3, 1>;
  using Iso = Eigen::Transform<Scalar, 3, Eigen::Isometry>;
  Iso transform = Iso::Identity();
  Vec velocity = Vec::Zero(), angular = Vec::Zero();
  std::vector<LinkPose<Scalar>> poses;
  for (std::size_t i = 0; i < arm.origins.size(); ++i) {
    const Iso origin = arm.origins[i].cast<Scalar>();
    const Vec axis = arm.axes[i].cast<Scalar>();
    const Scalar angle = Scalar(q0[i]) + Scalar(qd[i]) * t;
    Iso next = transform * origin;
    const Vec axis_world = next.linear() * axis;
    next.linear() = next.linear() * Eigen::AngleAxis<Scalar>(angle, axis).toRotationMatrix();
    velocity = velocity + angular.cross(Vec(next.translation() - transform.translation()));
    angular = angular + axis_world * Scalar(qd[i]);
    transform = next;
    poses.push_back({transform, velocity, angular});
  }
  return poses;
}

/// A link's collision shape's pose: its link frame's times the collision's origin.
template <class Scalar>
Eigen::Transform<Scalar, 3, Eigen::Isometry> shapePose(const LinkPose<Scalar>& link,
                                                       const core::ObstacleSpec& spec) {
  Eigen::Transform<Scalar, 3, Eigen::Isometry> local =
      Eigen::Transform<Scalar, 3, Eigen::Isometry>::Identity();
  local.translation() = spec.position.cast<Scalar>();
  local.linear() = spec.orientation.toRotationMatrix().cast<Scalar>();
  return link.transform * local;
}

/// The distance from p (in the shape's axes) to a URDF cylinder along z or a box, by its own
/// formula.
LD distanceTo(const core::ObstacleSpec& spec, const Eigen::Matrix<LD, 3, 1>& p) {
  if (spec.shape == core::ObstacleShape::kBox) {
    LD outside = 0, inside = -INFINITY;
    for (int i = 0; i < 3; ++i) {
      const LD d = std::abs(p[i]) - LD(spec.size[i]) / 2;
      outside += d > 0 ? d * d : 0;
      inside = std::max(inside, d);
    }
    return outside > 0 ? std::sqrt(outside) : inside;
  }
  const LD radial = std::hypot(p.x(), p.y()) - LD(spec.radius);
  const LD axial = std::abs(p.z()) - LD(spec.length) / 2;
  if (radial > 0 && axial > 0) return std::hypot(radial, axial);
  return std::max(radial, axial);
}

struct Throw {
  V centre, velocity;
  std::vector<double> q0, qd;
};

std::vector<Throw> makeThrows() {
  std::mt19937_64 random(42);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<Throw> throws;
  while (throws.size() < kThrows) {
    Throw t;
    for (int i = 0; i < 7; ++i) {
      t.q0.push_back(unit(random));
      t.qd.push_back(2 * unit(random));
    }
    const V target(0.3 * unit(random), 0.3 * unit(random), 0.7 + 0.5 * unit(random));
    const V from = target + V(unit(random), unit(random), 0.5 * unit(random)).normalized() *
                                (1.0 + 0.2 * unit(random));
    t.centre = from;
    t.velocity = (target - from).normalized() * (3 + unit(random));
    throws.push_back(t);
  }
  return throws;
}

/// The exact first contact along the arm's true motion within `end`: conservative advancement on
/// the least distance to a link (no link point moves faster than sum |qd| 1.5 m: the arm is
/// 1.41 m tall), stopped at 1e-13 m; `clear` false within 1e-9 m of a graze.
struct Exact {
  std::optional<LD> time;
  bool clear = true;
};
Exact exactContact(const Arm& arm, const Throw& t, double end) {
  using LV = Eigen::Matrix<LD, 3, 1>;
  LD speed = t.velocity.norm();
  for (const double rate : t.qd) speed += 1.5L * std::abs(rate);
  const auto gap = [&](LD time) {
    const auto poses = kinematics<LD>(arm, t.q0, t.qd, time);
    const LV centre = t.centre.cast<LD>() + time * t.velocity.cast<LD>();
    LD least = INFINITY;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const LV local = shapePose(poses[i], arm.obstacles[i]).inverse() * centre;
      least = std::min(least, distanceTo(arm.obstacles[i], local));
    }
    return least - LD(kRadius);
  };
  Exact exact;
  LD time = 0, least = INFINITY;
  while (time <= end) {
    const LD g = gap(time);
    least = std::min(least, g);
    if (g <= 1e-13L) {
      exact.time = time;
      LD deepest = 0;
      for (LD after = 1e-7L; after < 0.05L; after *= 2)
        deepest = std::min(deepest, gap(time + after));
      exact.clear = deepest < -1e-9L;
      return exact;
    }
    time += g / speed;
  }
  exact.clear = least > 1e-9L;
  return exact;
}

/// One update of one throw: the ball at its start, the links at its start and end.
struct Update {
  std::size_t throw_index = 0;
  double start = 0.0;
  V centre, velocity;
  std::vector<LinkPose<double>> from, to;
};

struct Setup {
  Arm arm = loadArm();
  std::vector<Throw> throws = makeThrows();
  std::vector<Exact> exact;
  std::vector<std::vector<Update>> updates;  // each throw's, up to its exact contact (or 0.4 s)
  Setup() {
    for (std::size_t k = 0; k < throws.size(); ++k) {
      const Throw& t = throws[k];
      exact.push_back(exactContact(arm, t, 0.4));
      const double last = exact.back().time ? static_cast<double>(*exact.back().time) + 0.01 : 0.4;
      std::vector<Update> list;
      for (int n = 0; n * kStep < last; ++n) {
        Update u;
        u.throw_index = k;
        u.start = n * kStep;
        u.centre = t.centre + u.start * t.velocity;
        u.velocity = t.velocity;
        u.from = kinematics<double>(arm, t.q0, t.qd, u.start);
        u.to = kinematics<double>(arm, t.q0, t.qd, u.start + kStep);
        list.push_back(std::move(u));
      }
      updates.push_back(std::move(list));
    }
  }
};
const Setup& setup() {
  static const Setup kSetup;
  return kSetup;
}

/// An engine's first contact within an update, as a share of it (0 to 1), or none.
using Query = std::function<std::optional<double>(const Update&)>;

/// Runs `query` on every update of every throw (one benchmark iteration an update: seven links),
/// then each throw's first contact from its updates in order, against the exact instant.
void sideBySide(benchmark::State& state, const Query& query) {
  const Setup& s = setup();
  std::vector<const Update*> all;
  for (const auto& list : s.updates) {
    for (const Update& u : list) all.push_back(&u);
  }
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(query(*all[i % all.size()]));
    ++i;
  }
  double largest = 0, sum = 0;
  int both = 0, disagree = 0, counted = 0;
  for (std::size_t k = 0; k < s.throws.size(); ++k) {
    if (!s.exact[k].clear) continue;
    ++counted;
    std::optional<double> found;
    for (const Update& u : s.updates[k]) {
      if (const auto share = query(u)) {
        found = u.start + *share * kStep;
        break;
      }
    }
    const auto& exact = s.exact[k].time;
    if (found.has_value() != exact.has_value()) {
      ++disagree;
      continue;
    }
    if (!found) continue;
    ++both;
    const double error = static_cast<double>(std::abs(LD(*found) - *exact));
    largest = std::max(largest, error);
    sum += error;
  }
  state.counters["throws"] = counted;
  state.counters["hits"] = both;
  state.counters["hit_or_miss_differs"] = disagree;
  state.counters["toi_error_max_s"] = largest;
  state.counters["toi_error_mean_s"] = both > 0 ? sum / both : 0.0;
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

void BM_ArmOurs(benchmark::State& state) {
  const Arm& arm = setup().arm;
  sideBySide(state, [&](const Update& u) -> std::optional<double> {
    core::BallMotion ball;
    ball.centre = u.centre;
    ball.velocity = u.velocity;
    ball.radius = kRadius;
    std::optional<double> first;
    for (std::size_t i = 0; i < arm.obstacles.size(); ++i) {
      core::RigidPose frame;
      frame.transform = u.from[i].transform;
      frame.velocity = u.from[i].velocity;
      frame.angular_velocity = u.from[i].angular;
      const core::PlacedShape placed = core::place(arm.obstacles[i], frame);
      const auto t =
          core::firstContact(ball, placed, placed.pose.velocity, V::Zero(), false, kStep);
      if (t && (!first || *t < *first)) first = t;
    }
    if (first) return *first / kStep;
    return std::nullopt;
  });
}
BENCHMARK(BM_ArmOurs);

#ifdef COLLISION_RESPONSE_WITH_BULLET
btTransform toBullet(const Eigen::Isometry3d& pose) {
  btTransform transform;
  const Eigen::Matrix3d& r = pose.linear();
  transform.setBasis(btMatrix3x3(btScalar(r(0, 0)), btScalar(r(0, 1)), btScalar(r(0, 2)),
                                 btScalar(r(1, 0)), btScalar(r(1, 1)), btScalar(r(1, 2)),
                                 btScalar(r(2, 0)), btScalar(r(2, 1)), btScalar(r(2, 2))));
  const V& p = pose.translation();
  transform.setOrigin(btVector3(btScalar(p.x()), btScalar(p.y()), btScalar(p.z())));
  return transform;
}

void BM_ArmBullet(benchmark::State& state) {
  const Arm& arm = setup().arm;
  std::vector<std::unique_ptr<btConvexShape>> shapes;
  for (const core::ObstacleSpec& spec : arm.obstacles) {
    if (spec.shape == core::ObstacleShape::kBox) {
      const V half = spec.size / 2;
      shapes.push_back(std::make_unique<btBoxShape>(
          btVector3(btScalar(half.x()), btScalar(half.y()), btScalar(half.z()))));
    } else {
      shapes.push_back(std::make_unique<btCylinderShapeZ>(
          btVector3(btScalar(spec.radius), btScalar(spec.radius), btScalar(spec.length / 2))));
    }
    shapes.back()->setMargin(0);
  }
  btSphereShape sphere{btScalar(kRadius)};
  sideBySide(state, [&](const Update& u) -> std::optional<double> {
    Eigen::Isometry3d ball_from = Eigen::Isometry3d::Identity(), ball_to = ball_from;
    ball_from.translation() = u.centre;
    ball_to.translation() = u.centre + kStep * u.velocity;
    std::optional<double> first;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      btVoronoiSimplexSolver simplex;
      btGjkEpaPenetrationDepthSolver depth;
      btContinuousConvexCollision cast(&sphere, shapes[i].get(), &simplex, &depth);
      btConvexCast::CastResult result;
      if (cast.calcTimeOfImpact(toBullet(ball_from), toBullet(ball_to),
                                toBullet(shapePose(u.from[i], arm.obstacles[i])),
                                toBullet(shapePose(u.to[i], arm.obstacles[i])), result)) {
        const double share = static_cast<double>(result.m_fraction);
        if (!first || share < *first) first = share;
      }
    }
    return first;
  });
}
BENCHMARK(BM_ArmBullet);
#endif

#ifdef COLLISION_RESPONSE_WITH_FCL
/// FCL's continuousCollide of the ball with each link, as `request` says (0: its defaults, 10
/// samples of a translation; 1: screw motion, the links turning).
void BM_ArmFcl(benchmark::State& state) {
  const Arm& arm = setup().arm;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> shapes;
  for (const core::ObstacleSpec& spec : arm.obstacles) {
    if (spec.shape == core::ObstacleShape::kBox) {
      shapes.push_back(std::make_shared<fcl::Boxd>(spec.size.x(), spec.size.y(), spec.size.z()));
    } else {
      shapes.push_back(std::make_shared<fcl::Cylinderd>(spec.radius, spec.length));
    }
  }
  fcl::Sphered sphere(kRadius);
  fcl::ContinuousCollisionRequestd request;
  if (state.range(0) == 1) request.ccd_motion_type = fcl::CCDM_SCREW;
  sideBySide(state, [&](const Update& u) -> std::optional<double> {
    fcl::Transform3d ball_from = fcl::Transform3d::Identity(), ball_to = ball_from;
    ball_from.translation() = u.centre;
    ball_to.translation() = u.centre + kStep * u.velocity;
    std::optional<double> first;
    for (std::size_t i = 0; i < shapes.size(); ++i) {
      fcl::ContinuousCollisionResultd result;
      fcl::continuousCollide(&sphere, ball_from, ball_to, shapes[i].get(),
                             shapePose(u.from[i], arm.obstacles[i]),
                             shapePose(u.to[i], arm.obstacles[i]), request, result);
      if (result.is_collide && (!first || result.time_of_contact < *first)) {
        first = result.time_of_contact;
      }
    }
    return first;
  });
}
BENCHMARK(BM_ArmFcl)->Arg(0)->Arg(1);
#endif

}  // namespace

BENCHMARK_MAIN();

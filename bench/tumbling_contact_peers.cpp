// A tumbling box's first contact beside Bullet's convex cast and FCL's continuous collision
// (issue 42, step 9; doc/performance.md, "First contact of a tumbling body"): the same box (0.3 x
// 0.2 x 0.1 m) in four motions whose first contact is known independently, each asked over the
// step of 10 ms (and of 1 ms) that holds it:
//   falls flat onto the floor       the parabola's instant, sqrt(2 (z0 - c) / g);
//   turns about a fixed centre      at w about its x axis, the centre fixed at z0 above the
//                                   floor: its lowest corner at z0 - (b sin wt + c cos wt), the
//                                   floor met at w t = atan2(b, c) - acos(z0 / sqrt(b^2 + c^2));
//   falls tumbling onto the floor   thrown up spinning at a constant w (isotropic moments):
//   falls tumbling onto a box         the root of the lowest corner's height in closed form, its
//                                   centre on the parabola, its orientation exp(t [w]) R0, in
//                                   long double by bisection (the table's top face as the floor).
// Ours: firstContact on the exact motion (tumbling_contact.h). The peers see the exact poses at
// the step's start and end only: Bullet's btContinuousConvexCollision moves between them at a
// constant linear and angular velocity (btTransformUtil: straight, turning about the centre);
// FCL's continuousCollide as its request says: its defaults (CCDM_TRANS: the start's
// orientation carried straight; CCDC_NAIVE: 10 samples, the first found inside), CCDM_LINEAR (its
// InterpMotion: straight and turning about the centre) and CCDM_SCREW (the screw between the
// poses), sampled; and CCDC_CONSERVATIVE_ADVANCEMENT. Where a peer's motion is not the true one
// (a chord for the parabola, a screw for a fall), its error holds the motion's too. Prints one
// Markdown table: each query's error of the instant (s; > 0: late, the bodies inside by then),
// CPU per query (thread CPU time over repetitions) and its ratio to ours (ours: its advancement
// steps). About 3 s.
//   cmake --build .ws/build --target tumbling_contact_peers
//   .ws/devel/lib/collision_response/tumbling_contact_peers
// Or bash scripts/tumbling_contact_peers.sh (installs Bullet and FCL first).
#include <time.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/tumbling_contact.h"

#ifdef COLLISION_RESPONSE_WITH_BULLET
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletCollision/NarrowPhaseCollision/btContinuousConvexCollision.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <btBulletCollisionCommon.h>
#endif
#ifdef COLLISION_RESPONSE_WITH_FCL
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/halfspace.h>
#include <fcl/narrowphase/continuous_collision.h>
#endif

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using L = long double;
using VL = Eigen::Matrix<L, 3, 1>;
const V kHalf(0.15, 0.1, 0.05);  // m: the box's half sizes a, b, c

/// One motion of the box: its centre on a parabola, turning at a constant w (isotropic moments,
/// or about a principal axis), and what it meets (a floor at z = 0 or a table's top face).
struct Case {
  std::string name;
  V position, velocity, gravity, angular_velocity, moments;
  Eigen::Quaterniond orientation;
  bool table = false;  ///< the table: half sizes (0.5, 0.5, 0.2) at (0.3, 0, 0.2), its top z = 0.4
  L exact = 0;         ///< s: the first contact, found independently (exactInstant)
};

const V kTableHalf(0.5, 0.5, 0.2), kTableCentre(0.3, 0, 0.2);

/// The pose at `t` of the exact motion, in closed form (in type T: double for the peers' poses,
/// long double for the exact instant).
template <typename T>
Eigen::Transform<T, 3, Eigen::Isometry> poseAt(const Case& c, T t) {
  using VT = Eigen::Matrix<T, 3, 1>;
  const VT w = c.angular_velocity.cast<T>();
  Eigen::Quaternion<T> q = c.orientation.cast<T>();
  if (w.norm() > 0) q = Eigen::Quaternion<T>(Eigen::AngleAxis<T>(w.norm() * t, w / w.norm())) * q;
  Eigen::Transform<T, 3, Eigen::Isometry> pose =
      Eigen::Transform<T, 3, Eigen::Isometry>::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() =
      c.position.cast<T>() + t * c.velocity.cast<T>() + (t * t / 2) * c.gravity.cast<T>();
  return pose;
}

/// m: the box's lowest point above the surface it falls on at `t` (its centre's height less the
/// box's support along -z, sum_i h_i |R_zi|).
L heightAt(const Case& c, L t) {
  const auto pose = poseAt<L>(c, t);
  L reach = 0;
  for (int i = 0; i < 3; ++i) reach += static_cast<L>(kHalf[i]) * std::fabs(pose.linear()(2, i));
  const L surface = c.table ? static_cast<L>(kTableCentre.z() + kTableHalf.z()) : L(0);
  return pose.translation().z() - reach - surface;
}

/// s: the first root of heightAt: scanned at 1e-5 s (the height's rate is at most a few m/s and
/// a box's corner-to-corner turn takes far longer than a scan step), then bisected to the last
/// bit of long double.
L exactInstant(const Case& c) {
  L before = 0;
  while (heightAt(c, before + L(1e-5)) > 0) before += L(1e-5);
  L after = before + L(1e-5);
  for (int i = 0; i < 200 && after - before > 0; ++i) {
    const L mid = (before + after) / 2;
    if (mid <= before || mid >= after) break;
    (heightAt(c, mid) > 0 ? before : after) = mid;
  }
  return after;
}

double cpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/// A query over the step [from, from + step]: the instant it finds (absolute), or none.
using Query = std::function<std::optional<double>(double from, double step)>;

struct Measured {
  std::optional<double> instant;
  double cpu = 0.0;  ///< s per query
};

Measured measure(const Query& query, double from, double step) {
  Measured m;
  m.instant = query(from, step);
  int runs = 0;
  const double began = cpuSeconds();
  double spent = 0.0;
  do {
    for (int i = 0; i < 8; ++i) (void)query(from, step);
    runs += 8;
    spent = cpuSeconds() - began;
  } while (spent < 0.05);
  m.cpu = spent / runs;
  return m;
}

TumblingBody bodyOf(const Case& c) {
  return TumblingBody::create(Cuboid{kHalf}, c.moments, 0.0, c.position, c.velocity, c.gravity,
                              c.orientation, c.angular_velocity)
      .value();
}

PlacedShape obstacleOf(const Case& c) {
  PlacedShape obstacle;
  if (c.table) {
    obstacle.shape = Cuboid{kTableHalf};
    obstacle.pose.transform.translation() = kTableCentre;
  } else {
    obstacle.shape = Plane{V::UnitZ(), 0.0};
  }
  return obstacle;
}

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
#endif

struct Engine {
  std::string name;
  std::function<Query(const Case&)> make;
};

std::vector<Engine> engines() {
  std::vector<Engine> all;
  all.push_back({"ours", [](const Case& c) -> Query {
                   const TumblingBody body = bodyOf(c);
                   const PlacedShape obstacle = obstacleOf(c);
                   return [body, obstacle](double from, double step) -> std::optional<double> {
                     const FirstContactResult r = firstContact(body, obstacle, from, step);
                     if (!r.contact) return std::nullopt;
                     return r.contact->time;
                   };
                 }});
#ifdef COLLISION_RESPONSE_WITH_BULLET
  all.push_back(
      {"Bullet", [](const Case& c) -> Query {
         auto box = std::make_shared<btBoxShape>(
             btVector3(btScalar(kHalf.x()), btScalar(kHalf.y()), btScalar(kHalf.z())));
         box->setMargin(0);  // the box's own faces, not rounded by a margin
         auto table = std::make_shared<btBoxShape>(btVector3(
             btScalar(kTableHalf.x()), btScalar(kTableHalf.y()), btScalar(kTableHalf.z())));
         table->setMargin(0);
         auto floor = std::make_shared<btStaticPlaneShape>(btVector3(0, 0, 1), btScalar(0));
         Eigen::Isometry3d table_pose = Eigen::Isometry3d::Identity();
         table_pose.translation() = kTableCentre;
         const bool on_table = c.table;
         return [c, box, table, floor, table_pose, on_table](double from,
                                                             double step) -> std::optional<double> {
           btVoronoiSimplexSolver simplex;
           btGjkEpaPenetrationDepthSolver depth;
           btConvexCast::CastResult result;
           const btTransform a0 = toBullet(poseAt<double>(c, from));
           const btTransform a1 = toBullet(poseAt<double>(c, from + step));
           const btTransform b = toBullet(on_table ? table_pose : Eigen::Isometry3d::Identity());
           bool hit = false;
           if (on_table) {
             btContinuousConvexCollision cast(box.get(), table.get(), &simplex, &depth);
             hit = cast.calcTimeOfImpact(a0, a1, b, b, result);
           } else {
             btContinuousConvexCollision cast(box.get(), floor.get());
             hit = cast.calcTimeOfImpact(a0, a1, b, b, result);
           }
           if (!hit) return std::nullopt;
           return from + static_cast<double>(result.m_fraction) * step;
         };
       }});
#endif
#ifdef COLLISION_RESPONSE_WITH_FCL
  struct FclVariant {
    const char* name;
    fcl::CCDMotionType motion;
    fcl::CCDSolverType solver;
  };
  for (const FclVariant& v :
       {FclVariant{"FCL defaults", fcl::CCDM_TRANS, fcl::CCDC_NAIVE},
        FclVariant{"FCL linear", fcl::CCDM_LINEAR, fcl::CCDC_NAIVE},
        FclVariant{"FCL screw", fcl::CCDM_SCREW, fcl::CCDC_NAIVE},
        FclVariant{"FCL screw, CA", fcl::CCDM_SCREW, fcl::CCDC_CONSERVATIVE_ADVANCEMENT}}) {
    all.push_back({v.name, [v](const Case& c) -> Query {
                     auto box =
                         std::make_shared<fcl::Boxd>(2 * kHalf.x(), 2 * kHalf.y(), 2 * kHalf.z());
                     std::shared_ptr<fcl::CollisionGeometryd> other;
                     fcl::Transform3d other_pose = fcl::Transform3d::Identity();
                     if (c.table) {
                       other = std::make_shared<fcl::Boxd>(2 * kTableHalf.x(), 2 * kTableHalf.y(),
                                                           2 * kTableHalf.z());
                       other_pose.translation() = kTableCentre;
                     } else if (v.solver == fcl::CCDC_CONSERVATIVE_ADVANCEMENT) {
                       // FCL 0.7's advancement against a Halfspace calls a null support
                       // function (libccd's GJK distance: a crash); a 20 m box, its top at z = 0,
                       // is the same floor here.
                       other = std::make_shared<fcl::Boxd>(20.0, 20.0, 1.0);
                       other_pose.translation() = V(0, 0, -0.5);
                     } else {
                       other = std::make_shared<fcl::Halfspaced>(V::UnitZ(), 0.0);
                     }
                     fcl::ContinuousCollisionRequestd request;
                     request.ccd_motion_type = v.motion;
                     request.ccd_solver_type = v.solver;
                     return [c, box, other, other_pose, request](
                                double from, double step) -> std::optional<double> {
                       fcl::ContinuousCollisionResultd result;
                       fcl::continuousCollide(box.get(), poseAt<double>(c, from),
                                              poseAt<double>(c, from + step), other.get(),
                                              other_pose, other_pose, request, result);
                       if (!result.is_collide) return std::nullopt;
                       return from + result.time_of_contact * step;
                     };
                   }});
  }
#endif
  return all;
}

std::vector<Case> cases() {
  const V g(0, 0, -9.81);
  // The box's principal moments per unit mass times 3 (b^2 + c^2, a^2 + c^2, a^2 + b^2): turning
  // about x alone, its rotation is steady.
  const V box_moments(kHalf.y() * kHalf.y() + kHalf.z() * kHalf.z(),
                      kHalf.x() * kHalf.x() + kHalf.z() * kHalf.z(),
                      kHalf.x() * kHalf.x() + kHalf.y() * kHalf.y());
  const Eigen::Quaterniond turned = Eigen::Quaterniond(0.48, 0.64, 0.36, 0.48).normalized();
  std::vector<Case> all;
  Case flat{"falls flat onto the floor",   V(0, 0, 1), V(0.5, 0.2, 0), g, V::Zero(), box_moments,
            Eigen::Quaterniond::Identity()};
  flat.exact = std::sqrt(2 * (L(1) - static_cast<L>(kHalf.z())) / L(9.81));
  all.push_back(flat);
  Case turning{"turns at 10 rad/s about a fixed centre onto the floor",
               V(0, 0, 0.1),
               V::Zero(),
               V::Zero(),
               V(10, 0, 0),
               box_moments,
               Eigen::Quaterniond::Identity()};
  const L b = static_cast<L>(kHalf.y()), c = static_cast<L>(kHalf.z());
  turning.exact = (std::atan2(b, c) - std::acos(L(0.1) / std::sqrt(b * b + c * c))) / L(10);
  all.push_back(turning);
  Case tumbling{"falls tumbling (w = (3, -5, 12) rad/s) onto the floor",
                V(0, 0, 1),
                V(0.5, 0.2, 1.0),
                g,
                V(3, -5, 12),
                V(1, 1, 1),
                turned};
  tumbling.exact = exactInstant(tumbling);
  all.push_back(tumbling);
  Case onto_box = tumbling;
  onto_box.name = "falls tumbling onto a box (a table)";
  onto_box.position = V(0, 0, 1.4);
  onto_box.table = true;
  onto_box.exact = exactInstant(onto_box);
  all.push_back(onto_box);
  // The closed forms against the bisection, and the table's corner within its top face.
  for (const Case& k : all) {
    const L root = exactInstant(k);
    if (std::fabs(root - k.exact) > L(1e-15)) {
      std::fprintf(stderr, "%s: closed form %.17Lg, root %.17Lg\n", k.name.c_str(), k.exact, root);
      std::exit(1);
    }
  }
  const auto pose = poseAt<L>(onto_box, onto_box.exact);
  for (int i = 0; i < 8; ++i) {
    const VL corner = pose * VL((i & 1 ? 1 : -1) * static_cast<L>(kHalf.x()),
                                (i & 2 ? 1 : -1) * static_cast<L>(kHalf.y()),
                                (i & 4 ? 1 : -1) * static_cast<L>(kHalf.z()));
    if (corner.z() < L(0.4) + L(1e-9) &&
        (std::fabs(corner.x() - L(0.3)) >= L(0.5) || std::fabs(corner.y()) >= L(0.5))) {
      std::fprintf(stderr, "the corner meets the table off its top face\n");
      std::exit(1);
    }
  }
  return all;
}

std::string seconds(double s) {
  char text[32];
  if (s >= 1e-3) {
    std::snprintf(text, sizeof text, "%.3g ms", s * 1e3);
  } else {
    std::snprintf(text, sizeof text, "%.3g us", s * 1e6);
  }
  return text;
}

int run() {
#ifndef COLLISION_RESPONSE_WITH_BULLET
  std::printf("Bullet (libbullet-dev) not found at configure time: not beside ours\n");
#endif
#ifndef COLLISION_RESPONSE_WITH_FCL
  std::printf("FCL (libfcl-dev) not found at configure time: not beside ours\n");
#endif
  const std::vector<Engine> all = engines();
  std::printf("| case (exact instant) | step |");
  for (const Engine& engine : all) std::printf(" %s |", engine.name.c_str());
  std::printf("\n|---|---|");
  for (std::size_t i = 0; i < all.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const Case& c : cases()) {
    for (const double step : {0.01, 0.001}) {
      // The step that holds the instant, started where a fixed-rate loop would start it.
      const double from = std::floor(static_cast<double>(c.exact) / step) * step;
      std::printf("| %s (%.6f s) | %g ms |", c.name.c_str(), static_cast<double>(c.exact),
                  step * 1e3);
      double ours = 0.0;
      for (const Engine& engine : all) {
        const Measured m = measure(engine.make(c), from, step);
        if (&engine == &all.front()) ours = m.cpu;
        if (m.instant) {
          std::printf(" %+.1e s,", static_cast<double>(static_cast<L>(*m.instant) - c.exact));
        } else {
          std::printf(" **missed**,");
        }
        std::printf(" %s", seconds(m.cpu).c_str());
        if (&engine == &all.front()) {
          // Ours: its advancement steps too (each one orientation and one gap).
          std::printf(", %d steps", firstContact(bodyOf(c), obstacleOf(c), from, step).steps);
        } else {
          std::printf(" (%.2g x)", m.cpu / ours);
        }
        std::printf(" |");
      }
      std::printf("\n");
    }
  }
  return 0;
}

}  // namespace
}  // namespace collision_response::core

int main() { return collision_response::core::run(); }

// Bodies and faces for the lasting-contact tests (test_shaped_lasting.cpp,
// test_shaped_edge_tip.cpp, test_shaped_pivot.cpp, test_shaped_rim.cpp): a box's and a
// cylinder's moments in closed form, the energy a motion has at an instant.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "contact/shaped_lasting.h"

namespace collision_response::core::lasting_bodies {

using V = Eigen::Vector3d;
using Q = Eigen::Quaterniond;

inline constexpr double kG = 9.81;
inline const V kDown(0, 0, -kG);

inline LastingBody box(const V& half, double mass, const V& centre,
                       const Q& orientation = Q::Identity()) {
  LastingBody body;
  body.shape = Cuboid{half};
  body.mass = mass;
  // m / 12 (b^2 + c^2) with b, c the edges: m / 3 times the half sizes' squares.
  body.moments =
      mass / 3 *
      V(half.y() * half.y() + half.z() * half.z(), half.x() * half.x() + half.z() * half.z(),
        half.x() * half.x() + half.y() * half.y());
  body.centre = centre;
  body.orientation = orientation;
  body.gravity = kDown;
  return body;
}

inline LastingBody cylinder(double radius, double half_length, double mass, double axial,
                            const V& centre, const Q& orientation) {
  LastingBody body;
  body.shape = Cylinder{radius, half_length};
  body.mass = mass;
  const double across = mass * (3 * radius * radius + 4 * half_length * half_length) / 12;
  body.moments = V(across, across, axial);
  body.centre = centre;
  body.orientation = orientation;
  body.gravity = kDown;
  return body;
}

inline FlatFace plane(const V& normal, double mu) {
  FlatFace face;
  face.normal = normal;
  face.friction = mu;
  return face;
}

/// The lasting tests' table top: z = 0.7, x in [-1, 1] (its edge at x = 1), y in [-0.5, 0.5];
/// its corner (1, 0.5, 0.7).
inline FlatFace tableTop(double mu) {
  FlatFace table = plane(V::UnitZ(), mu);
  table.point = V(0, 0, 0.7);
  table.bounded = true;
  table.half_extent = Eigen::Vector2d(1, 0.5);
  return table;
}

inline double energy(const LastingBody& body, const LastingMotion& motion, double t) {
  const Eigen::Matrix3d r = motion.orientationAt(t).toRotationMatrix();
  const Eigen::Matrix3d inertia = r * body.moments.asDiagonal() * r.transpose();
  const V v = motion.velocityAt(t), w = motion.angularVelocityAt(t);
  return 0.5 * body.mass * v.squaredNorm() + 0.5 * w.dot(inertia * w) -
         body.mass * body.gravity.dot(motion.centreAt(t));
}

/// The body as `motion` has it at `t`: to ask lastingOnFace again from there.
inline LastingBody bodyAt(const LastingBody& body, const LastingMotion& motion, double t) {
  LastingBody there = body;
  there.time = t;
  there.centre = motion.centreAt(t);
  there.velocity = motion.velocityAt(t);
  there.angular_velocity = motion.angularVelocityAt(t);
  there.orientation = motion.orientationAt(t);
  return there;
}

inline std::string errorOf(const Expected<LastingMotion>& motion) {
  return motion.ok() ? std::string("(no error)") : motion.error().message();
}

}  // namespace collision_response::core::lasting_bodies

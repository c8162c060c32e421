// Bullet 3 replays the cube tosses (only in the benchmark; the product never links Bullet):
// btDiscreteDynamicsWorld with its defaults (sequential impulses, 10 iterations, restitution
// below 0.2 m/s of approach dropped, warm starting, sleeping), a btBoxShape cube over a
// btStaticPlaneShape table, one fixed step of kStep s per stepSimulation.
#include <btBulletDynamicsCommon.h>

#include "cube_tosses.h"

namespace collision_response::bench::cube_tosses {
namespace {

// Debian's Bullet is built in single precision: btScalar is float.
btScalar bt(double value) { return static_cast<btScalar>(value); }
btVector3 bt(const V& v) { return btVector3(bt(v.x()), bt(v.y()), bt(v.z())); }

std::vector<Pose> play(const Contact& contact, const State& first, std::size_t samples) {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
  world.setGravity(btVector3(0, 0, bt(-kGravity)));

  // Bullet multiplies the two bodies' coefficients (btManifoldResult's combined friction and
  // restitution): the table's are 1, the cube's the pair's.
  btStaticPlaneShape table_shape(btVector3(0, 0, 1), bt(kTableTop));
  btDefaultMotionState table_motion;
  btRigidBody::btRigidBodyConstructionInfo table_info(0, &table_motion, &table_shape);
  table_info.m_restitution = 1;
  table_info.m_friction = 1;
  btRigidBody table(table_info);
  world.addRigidBody(&table);

  btBoxShape cube_shape(btVector3(bt(kHalfWidth), bt(kHalfWidth), bt(kHalfWidth)));
  // Its collision margin Bullet's default (0.04 m): a btBoxShape keeps its size whatever its
  // margin, and its support points against the plane are its corners (btBoxShape::
  // localGetSupportingVertex); a margin of 1 mm gives the same figures to the last digit shown.
  btVector3 inertia(0, 0, 0);
  cube_shape.calculateLocalInertia(bt(kMass), inertia);
  btTransform start;
  start.setOrigin(bt(first.pose.position));
  const Q& q = first.pose.orientation;
  start.setRotation(btQuaternion(bt(q.x()), bt(q.y()), bt(q.z()), bt(q.w())));
  btDefaultMotionState cube_motion(start);
  btRigidBody::btRigidBodyConstructionInfo cube_info(bt(kMass), &cube_motion, &cube_shape, inertia);
  cube_info.m_restitution = bt(contact.restitution);
  cube_info.m_friction = bt(contact.friction);
  btRigidBody cube(cube_info);
  cube.setLinearVelocity(bt(first.velocity));
  cube.setAngularVelocity(bt(first.angular_velocity));  // world frame
  world.addRigidBody(&cube);

  std::vector<Pose> path;
  path.reserve(samples);
  for (std::size_t k = 0; k < samples; ++k) {
    if (k > 0) {
      for (int s = 0; s < kStepsPerSample; ++s) world.stepSimulation(bt(kStep), 0);
    }
    const btTransform& pose = cube.getCenterOfMassTransform();
    const btVector3& p = pose.getOrigin();
    const btQuaternion r = pose.getRotation();
    path.push_back(Pose{V(p.x(), p.y(), p.z()), Q(r.w(), r.x(), r.y(), r.z()).normalized()});
  }
  world.removeRigidBody(&cube);
  world.removeRigidBody(&table);
  return path;
}

}  // namespace

Peer bulletPeer() {
  return Peer{"Bullet",
              "Bullet " + std::to_string(btGetVersion() / 100) + "." +
                  std::to_string(btGetVersion() % 100) + " (" +
                  (sizeof(btScalar) == sizeof(float) ? "single" : "double") +
                  " precision), its defaults: sequential impulses, 10 iterations, "
                  "restitution threshold 0.2 m/s, warm starting, sleeping, margin 0.04 m; "
                  "1036 Hz; e and mu multiplied with the table's 1",
              true, [](const Contact& contact) -> Simulate {
                return [contact](const State& first, std::size_t samples) {
                  return play(contact, first, samples);
                };
              }};
}

}  // namespace collision_response::bench::cube_tosses

// Bullet 3 on the benchmark's scenes (only in the benchmark; the product never links Bullet).
#include <btBulletDynamicsCommon.h>

#include <memory>

#include "collision_response/core/triangle_mesh.h"
#include "harness.h"

namespace collision_response::bench {
namespace {

// Debian's Bullet is built in single precision: btScalar is float.
btScalar bt(double value) { return static_cast<btScalar>(value); }
btVector3 bt(const V& v) { return btVector3(bt(v.x()), bt(v.y()), bt(v.z())); }

}  // namespace

Engine bulletEngine(bool recommended) {
  return [recommended](const core::Scene& scene, const Play& play) {
    btDefaultCollisionConfiguration configuration;
    btCollisionDispatcher dispatcher(&configuration);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
    const V g = scene.effects.gravity ? scene.gravity : V::Zero();
    world.setGravity(bt(g));
    if (recommended) {
      // The settings Bullet's maintainers give for bouncing: restitution at any speed, no warm
      // starting, split impulse (position correction that adds no velocity), CCD on.
      btContactSolverInfo& info = world.getSolverInfo();
      info.m_restitutionVelocityThreshold = 0;
      info.m_solverMode &= ~SOLVER_USE_WARMSTARTING;
      info.m_splitImpulse = 1;
    }
    // Bullet multiplies the two bodies' restitutions
    // (btManifoldResult::calculateCombinedRestitution).
    const ProductRestitutions restitution = productRestitutions(scene);
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btTriangleMesh>> meshes;
    std::vector<std::unique_ptr<btDefaultMotionState>> motions;
    std::vector<std::unique_ptr<btRigidBody>> bodies, obstacles;
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
      const core::BodySpec& spec = scene.bodies[b];
      shapes.push_back(std::make_unique<btSphereShape>(bt(spec.radius)));
      btVector3 inertia(0, 0, 0);
      shapes.back()->calculateLocalInertia(bt(spec.mass), inertia);
      btTransform start;
      start.setIdentity();
      start.setOrigin(bt(spec.position));
      motions.push_back(std::make_unique<btDefaultMotionState>(start));
      btRigidBody::btRigidBodyConstructionInfo info(bt(spec.mass), motions.back().get(),
                                                    shapes.back().get(), inertia);
      info.m_restitution = bt(restitution.bodies[b]);
      info.m_friction = 0;
      info.m_rollingFriction = 0;
      info.m_linearDamping = 0;
      info.m_angularDamping = 0;
      bodies.push_back(std::make_unique<btRigidBody>(info));
      btRigidBody& body = *bodies.back();
      body.setLinearVelocity(bt(spec.velocity));
      body.setActivationState(DISABLE_DEACTIVATION);
      if (recommended) {
        body.setCcdMotionThreshold(static_cast<btScalar>(spec.radius));
        body.setCcdSweptSphereRadius(static_cast<btScalar>(0.5 * spec.radius));
      }
      world.addRigidBody(&body);
    }
    for (std::size_t o = 0; o < scene.obstacles.size(); ++o) {
      const core::ObstacleSpec& spec = scene.obstacles[o];
      if (spec.shape == core::ObstacleShape::kPlane) {
        const V n = spec.normal.normalized();
        shapes.push_back(std::make_unique<btStaticPlaneShape>(bt(n), bt(spec.offset)));
      } else if (spec.shape == core::ObstacleShape::kMesh) {
        // btBvhTriangleMeshShape over the mesh's triangles (its own hierarchy).
        meshes.push_back(std::make_unique<btTriangleMesh>());
        const auto corner = [&](std::uint32_t v) { return bt(spec.mesh->vertices()[v]); };
        for (const auto& t : spec.mesh->triangles()) {
          meshes.back()->addTriangle(corner(t[0]), corner(t[1]), corner(t[2]));
        }
        shapes.push_back(std::make_unique<btBvhTriangleMeshShape>(meshes.back().get(), true));
      } else if (spec.shape == core::ObstacleShape::kBox) {  // along the axes (the scenes' boxes)
        shapes.push_back(std::make_unique<btBoxShape>(bt(V(0.5 * spec.size))));
        shapes.back()->setMargin(0);
      } else {
        shapes.push_back(std::make_unique<btSphereShape>(bt(spec.radius)));
      }
      btTransform start;
      start.setIdentity();
      if (spec.shape != core::ObstacleShape::kPlane) start.setOrigin(bt(spec.position));
      motions.push_back(std::make_unique<btDefaultMotionState>(start));
      btRigidBody::btRigidBodyConstructionInfo info(0, motions.back().get(), shapes.back().get());
      info.m_restitution = bt(restitution.obstacles[o]);
      info.m_friction = 0;
      obstacles.push_back(std::make_unique<btRigidBody>(info));
      if (o < play.obstacle_velocities.size() && play.obstacle_velocities[o] != V::Zero()) {
        // A kinematic body: Bullet takes its velocity from its motion state's successive poses.
        obstacles.back()->setCollisionFlags(obstacles.back()->getCollisionFlags() |
                                            btCollisionObject::CF_KINEMATIC_OBJECT);
        obstacles.back()->setActivationState(DISABLE_DEACTIVATION);
      }
      world.addRigidBody(obstacles.back().get());
    }

    Run run;
    const auto updates = static_cast<long>(std::llround(play.duration * play.rate));
    const double dt = 1.0 / play.rate;
    std::vector<V> positions(bodies.size()), velocities(bodies.size());
    for (long k = 0; k <= updates; ++k) {
      if (k > 0) {
        // Moving obstacles: their motion states at the step's end.
        for (std::size_t o = 0; o < play.obstacle_velocities.size(); ++o) {
          if (play.obstacle_velocities[o] == V::Zero()) continue;
          btTransform pose;
          pose.setIdentity();
          pose.setOrigin(bt(V(scene.obstacles[o].position +
                              static_cast<double>(k) * dt * play.obstacle_velocities[o])));
          motions[scene.bodies.size() + o]->setWorldTransform(pose);
        }
        world.stepSimulation(bt(dt), 1, bt(dt));
      }
      for (std::size_t i = 0; i < bodies.size(); ++i) {
        const btVector3 p = bodies[i]->getCenterOfMassPosition();
        const btVector3 v = bodies[i]->getLinearVelocity();
        positions[i] = V(p.x(), p.y(), p.z());
        velocities[i] = V(v.x(), v.y(), v.z());
      }
      run.record(play, static_cast<double>(k) * dt, positions, velocities);
    }
    for (const auto& body : bodies) world.removeRigidBody(body.get());
    for (const auto& body : obstacles) world.removeRigidBody(body.get());
    return run;
  };
}

}  // namespace collision_response::bench

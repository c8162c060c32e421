// Bullet 3 on the benchmark's scenes (only in the benchmark; the product never links Bullet).
#include <btBulletDynamicsCommon.h>

#include <memory>

#include "harness.h"

namespace collision_response::bench {
namespace {

// Debian's Bullet is built in single precision: btScalar is float.
btScalar bt(double value) { return static_cast<btScalar>(value); }
btVector3 bt(const V& v) { return btVector3(bt(v.x()), bt(v.y()), bt(v.z())); }

}  // namespace

Engine bulletEngine(bool recommended) {
  return [recommended](const core::Scene& scene, double rate, double duration) {
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
    // Bullet multiplies the two bodies' restitutions. Where all balls share one material,
    // balls get sqrt(e_ball-ball) and obstacles e_ball-obstacle / sqrt(e_ball-ball), so that
    // every product is the scene's coefficient; where they do not (the drop test: balls never
    // meet), each ball gets its coefficient against the obstacles and the obstacles 1.
    const std::string& ball_material = scene.bodies.front().material;
    bool one_material = true;
    for (const core::BodySpec& spec : scene.bodies)
      one_material = one_material && spec.material == ball_material;
    const std::string& obstacle_material =
        scene.obstacles.empty() ? ball_material : scene.obstacles.front().material;
    const auto ball_restitution = [&](const core::BodySpec& spec) {
      return one_material ? std::sqrt(*scene.materials.restitution(ball_material, ball_material))
                          : *scene.materials.restitution(spec.material, obstacle_material);
    };
    const auto obstacle_restitution = [&](const core::ObstacleSpec& spec) {
      return one_material
                 ? *scene.materials.restitution(ball_material, spec.material) /
                       std::sqrt(*scene.materials.restitution(ball_material, ball_material))
                 : 1.0;
    };
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btDefaultMotionState>> motions;
    std::vector<std::unique_ptr<btRigidBody>> bodies, obstacles;
    for (const core::BodySpec& spec : scene.bodies) {
      shapes.push_back(std::make_unique<btSphereShape>(bt(spec.radius)));
      btVector3 inertia(0, 0, 0);
      shapes.back()->calculateLocalInertia(bt(spec.mass), inertia);
      btTransform start;
      start.setIdentity();
      start.setOrigin(bt(spec.position));
      motions.push_back(std::make_unique<btDefaultMotionState>(start));
      btRigidBody::btRigidBodyConstructionInfo info(bt(spec.mass), motions.back().get(),
                                                    shapes.back().get(), inertia);
      info.m_restitution = bt(ball_restitution(spec));
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
    for (const core::ObstacleSpec& spec : scene.obstacles) {
      if (spec.shape == core::ObstacleShape::kPlane) {
        const V n = spec.normal.normalized();
        shapes.push_back(std::make_unique<btStaticPlaneShape>(bt(n), bt(spec.offset)));
      } else {
        shapes.push_back(std::make_unique<btSphereShape>(bt(spec.radius)));
      }
      btTransform start;
      start.setIdentity();
      if (spec.shape == core::ObstacleShape::kSphere) {
        start.setOrigin(bt(spec.position));
      }
      motions.push_back(std::make_unique<btDefaultMotionState>(start));
      btRigidBody::btRigidBodyConstructionInfo info(0, motions.back().get(), shapes.back().get());
      info.m_restitution = bt(obstacle_restitution(spec));
      info.m_friction = 0;
      obstacles.push_back(std::make_unique<btRigidBody>(info));
      world.addRigidBody(obstacles.back().get());
    }

    Run run;
    const auto updates = static_cast<long>(std::llround(duration * rate));
    const double dt = 1.0 / rate;
    for (long k = 0; k <= updates; ++k) {
      if (k > 0) world.stepSimulation(bt(dt), 1, bt(dt));
      run.times.push_back(static_cast<double>(k) * dt);
      std::vector<V> positions, velocities;
      for (const auto& body : bodies) {
        const btVector3 p = body->getCenterOfMassPosition();
        const btVector3 v = body->getLinearVelocity();
        positions.emplace_back(p.x(), p.y(), p.z());
        velocities.emplace_back(v.x(), v.y(), v.z());
      }
      run.positions.push_back(positions);
      run.velocities.push_back(velocities);
    }
    for (const auto& body : bodies) world.removeRigidBody(body.get());
    for (const auto& body : obstacles) world.removeRigidBody(body.get());
    return run;
  };
}

}  // namespace collision_response::bench

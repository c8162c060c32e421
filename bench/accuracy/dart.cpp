// DART on the benchmark's scenes (only in the benchmark; the product never links DART).
//
// A dart::simulation::World: every ball a Skeleton of one body on a FreeJoint with a sphere
// ShapeNode (collision and dynamics aspects), every obstacle a Skeleton welded to the world; one
// World::step per state at the rate (time step 1/rate). Its defaults otherwise: the boxed-LCP
// constraint solver (Dantzig), and the FCL collision detector, with analytic primitives
// (FCLCollisionDetector::PRIMITIVE; its default, MESH, makes a sphere a triangle mesh). A plane
// is a box 200 m wide and 1 m thick whose face is the plane: FCL's broadphase (a dynamic AABB
// tree) crashes on the infinite box of a PlaneShape's fcl::Halfspace once a scene has several
// (seen here with the break's four cushions), and DART's MESH mode makes a plane such a box too.
// Friction 0.
//
// What DART decides for the user (dart/constraint/ContactConstraint.cpp, DART 6): the contact's
// restitution is the product of the two shapes' coefficients (set here so that every product is
// the scene's, as for Bullet); a contact bounces only when e times the approach speed exceeds
// DART_BOUNCING_VELOCITY_THRESHOLD = 0.1 m/s and never faster than DART_MAX_BOUNCING_VELOCITY =
// 100 m/s, both hard-coded (threshold 0 cannot be asked for); penetration is corrected at
// ERP 0.01 per step up to 1e-3 m/s. DART has no continuous collision detection: contacts are
// found in the overlap at each step.
#include <dart/collision/fcl/FCLCollisionDetector.hpp>
#include <dart/constraint/ConstraintSolver.hpp>
#include <dart/dynamics/BoxShape.hpp>
#include <dart/dynamics/FreeJoint.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/dynamics/SphereShape.hpp>
#include <dart/dynamics/WeldJoint.hpp>
#include <dart/simulation/World.hpp>

#include "harness.h"

namespace collision_response::bench {
namespace {

using dart::dynamics::BodyNode;
using dart::dynamics::CollisionAspect;
using dart::dynamics::DynamicsAspect;
using dart::dynamics::ShapeNode;

void setSurface(ShapeNode* shape, double restitution) {
  shape->getDynamicsAspect()->setRestitutionCoeff(restitution);
  shape->getDynamicsAspect()->setFrictionCoeff(0.0);
}

}  // namespace

Engine dartEngine() {
  // One detector for every world this engine makes (DART warns once when PRIMITIVE is chosen).
  auto detector = dart::collision::FCLCollisionDetector::create();
  detector->setPrimitiveShapeType(dart::collision::FCLCollisionDetector::PRIMITIVE);
  return [detector](const core::Scene& scene, const Play& play) {
    if (movesObstacles(play)) {
      Run run;
      run.unsupported = "no moving obstacles in this harness";
      return run;
    }
    if (hasMesh(scene)) {
      Run run;
      run.unsupported = "no triangle meshes in this harness";
      return run;
    }
    const double dt = 1.0 / play.rate;
    auto world = dart::simulation::World::create();
    world->setTimeStep(dt);
    world->setGravity(scene.effects.gravity ? scene.gravity : V::Zero());
    world->getConstraintSolver()->setCollisionDetector(detector);
    const ProductRestitutions restitution = productRestitutions(scene);

    std::vector<BodyNode*> bodies;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const core::BodySpec& spec = scene.bodies[i];
      auto skeleton = dart::dynamics::Skeleton::create("ball_" + std::to_string(i));
      auto [joint, body] = skeleton->createJointAndBodyNodePair<dart::dynamics::FreeJoint>();
      auto sphere = std::make_shared<dart::dynamics::SphereShape>(spec.radius);
      ShapeNode* shape = body->createShapeNodeWith<CollisionAspect, DynamicsAspect>(sphere);
      setSurface(shape, restitution.bodies[i]);
      dart::dynamics::Inertia inertia;
      inertia.setMass(spec.mass);
      inertia.setMoment(sphere->computeInertia(spec.mass));
      body->setInertia(inertia);
      // A free joint's coordinates: rotation then translation; its velocities (angular, linear)
      // in the body frame, which is the world's here (no rotation).
      Eigen::Vector6d positions = Eigen::Vector6d::Zero(), velocities = Eigen::Vector6d::Zero();
      positions.tail<3>() = spec.position;
      velocities.tail<3>() = spec.velocity;
      joint->setPositions(positions);
      joint->setVelocities(velocities);
      world->addSkeleton(skeleton);
      bodies.push_back(body);
    }
    for (std::size_t o = 0; o < scene.obstacles.size(); ++o) {
      const core::ObstacleSpec& spec = scene.obstacles[o];
      auto skeleton = dart::dynamics::Skeleton::create("obstacle_" + std::to_string(o));
      auto [joint, body] = skeleton->createJointAndBodyNodePair<dart::dynamics::WeldJoint>();
      std::shared_ptr<dart::dynamics::Shape> geometry;
      Eigen::Isometry3d placed = Eigen::Isometry3d::Identity();
      if (spec.shape == core::ObstacleShape::kPlane) {
        // The box's local z along the plane's normal, its top face on the plane.
        const V n = spec.normal.normalized();
        constexpr double kWidth = 200.0, kThickness = 1.0;
        geometry = std::make_shared<dart::dynamics::BoxShape>(V(kWidth, kWidth, kThickness));
        placed.linear() = Eigen::Quaterniond::FromTwoVectors(V::UnitZ(), n).toRotationMatrix();
        placed.translation() = n * (spec.offset - 0.5 * kThickness);
      } else if (spec.shape == core::ObstacleShape::kBox) {  // along the axes
        geometry = std::make_shared<dart::dynamics::BoxShape>(spec.size);
        placed.translation() = spec.position;
      } else {
        geometry = std::make_shared<dart::dynamics::SphereShape>(spec.radius);
        placed.translation() = spec.position;
      }
      joint->setTransformFromParentBodyNode(placed);
      setSurface(body->createShapeNodeWith<CollisionAspect, DynamicsAspect>(geometry),
                 restitution.obstacles[o]);
      skeleton->setMobile(false);
      world->addSkeleton(skeleton);
    }

    Run run;
    const auto updates = static_cast<long>(std::llround(play.duration * play.rate));
    std::vector<V> positions(bodies.size()), velocities(bodies.size());
    for (long k = 0; k <= updates; ++k) {
      if (k > 0) world->step();
      for (std::size_t i = 0; i < bodies.size(); ++i) {
        positions[i] = bodies[i]->getWorldTransform().translation();
        velocities[i] = bodies[i]->getLinearVelocity();
      }
      run.record(play, static_cast<double>(k) * dt, positions, velocities);
    }
    return run;
  };
}

}  // namespace collision_response::bench

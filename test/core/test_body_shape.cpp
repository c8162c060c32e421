// A scene body's shape and inertia (body_shape.h): each bad value named at its scene key by
// validateScene, before the refusals that stand for now ("not yet": an immovable shaped body in
// the monitor, any shaped body in a ball's prediction), which name the body; a
// ball's scene as before; each shape's mass properties its closed form's.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/scene.h"
#include "scene_builders.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
using scene_builders::ball;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A scene of one body, given its shape by `shape_it`, and a second body, a plain ball.
template <class ShapeIt>
Scene sceneWith(ShapeIt shape_it) {
  Scene scene;
  BodySpec body = ball("block", 0.37, 0.0, "hollow_hard_plastic_ball");
  shape_it(body);
  scene.bodies = {ball("ball", 0.0027, 0.02, "hollow_hard_plastic_ball"), body};
  return scene;
}

void expectRefused(const Status& status, const std::string& field, const std::string& words) {
  ASSERT_FALSE(status.ok()) << "expected a refusal naming " << field;
  EXPECT_EQ(status.error().field, field) << status.error().message();
  EXPECT_NE(status.error().reason.find(words), std::string::npos) << status.error().message();
}

void box(BodySpec& body) {
  body.shape = BodyShape::kBox;
  body.size = V(0.1048, 0.1048, 0.1048);
}

TEST(BodyShape, BallsAreAsBefore) {
  // A point mass (radius 0), a hollow ball and an immovable ball: accepted as they were.
  Scene scene = sceneWith([](BodySpec& body) { body.radius = 0.0; });
  scene.bodies.push_back(ball("wall_ball", kInf, 0.5, "hollow_hard_plastic_ball"));
  scene.bodies[0].inertia = Inertia::kHollow;
  EXPECT_TRUE(validateScene(scene, "scene").ok())
      << validateScene(scene, "scene").error().message();
}

// The monitor moves a box, a cylinder, a capsule, a mesh (its convex hull) and a sphere given a
// tensor (validateScene's default, MovingShapes::kMonitored); an immovable shaped body not yet,
// saying so.
// A ball's prediction (kSpheresOnly), whose other bodies are held as spheres, still refuses every
// shaped body by name: nothing silently becomes a ball.
TEST(BodyShape, TheMonitorMovesShapedBodiesButAnImmovableOneNotYet) {
  for (const auto& [shape, name] :
       {std::pair{BodyShape::kBox, "box"}, std::pair{BodyShape::kCylinder, "cylinder"},
        std::pair{BodyShape::kCapsule, "capsule"}, std::pair{BodyShape::kMesh, "mesh"}}) {
    Scene scene = sceneWith([&, shape_kind = shape](BodySpec& body) {
      body.shape = shape_kind;
      body.size = shape_kind == BodyShape::kBox ? V(0.1, 0.2, 0.3) : V::Zero();
      body.radius = shape_kind == BodyShape::kBox || shape_kind == BodyShape::kMesh ? 0.0 : 0.05;
      body.length =
          shape_kind == BodyShape::kCylinder || shape_kind == BodyShape::kCapsule ? 0.1 : 0.0;
      body.mesh = scene_builders::cubeMesh(V(0.05, 0.05, 0.05));
    });
    EXPECT_TRUE(validateScene(scene, "~scene").ok())
        << validateScene(scene, "~scene").error().message();
    expectRefused(validateScene(scene, "~scene", MovingShapes::kSpheresOnly),
                  "~scene/bodies[1]/shape",
                  std::string("not yet: only spheres move (body 'block' is a ") + name);
  }
  // An immovable one: not yet moved by the monitor, saying so.
  Scene immovable = sceneWith([](BodySpec& body) {
    box(body);
    body.mass = kInf;
  });
  expectRefused(validateScene(immovable, "s"), "s/bodies[1]/mass", "not yet");
  // A sphere given a tensor is a shaped body: the monitor moves it as one, a ball's prediction
  // does not take it.
  Scene tensor = sceneWith([](BodySpec& body) {
    body.radius = 0.05;
    body.inertia_tensor = InertiaTensor{1e-3, 1e-3, 1e-3, 0, 0, 0};
  });
  EXPECT_TRUE(validateScene(tensor, "s").ok()) << validateScene(tensor, "s").error().message();
  expectRefused(validateScene(tensor, "s", MovingShapes::kSpheresOnly), "s/bodies[1]/inertia",
                "not yet");
}

TEST(BodyShape, EachBadValueIsNamedAtItsKey) {
  const auto check = [](auto shape_it, const std::string& field, const std::string& words) {
    SCOPED_TRACE(field);
    expectRefused(validateScene(sceneWith(shape_it), "~scene"), field, words);
  };
  check(
      [](BodySpec& b) {
        box(b);
        b.size.y() = 0.0;
      },
      "~scene/bodies[1]/size", "> 0");
  check(
      [](BodySpec& b) {
        box(b);
        b.size.z() = kNan;
      },
      "~scene/bodies[1]/size.z", "finite");
  check(
      [](BodySpec& b) {
        b.shape = BodyShape::kCylinder;
        b.radius = 0.05;
      },
      "~scene/bodies[1]/length", "");
  check(
      [](BodySpec& b) {
        b.shape = BodyShape::kCapsule;
        b.radius = 0.05;
        b.length = -0.1;
      },
      "~scene/bodies[1]/length", ">= 0");
  check(
      [](BodySpec& b) {
        b.shape = BodyShape::kCapsule;
        b.length = 0.1;
      },
      "~scene/bodies[1]/radius", "");
  check([](BodySpec& b) { b.shape = BodyShape::kMesh; }, "~scene/bodies[1]/resource",
        "no loaded mesh");
  // A flat mesh: its hull has no volume.
  check(
      [](BodySpec& b) {
        b.shape = BodyShape::kMesh;
        b.mesh = scene_builders::floorMesh(2, 1.0);
      },
      "~scene/bodies[1]/resource", "spans no volume");
  // Hollow is a sphere's.
  check(
      [](BodySpec& b) {
        box(b);
        b.inertia = Inertia::kHollow;
      },
      "~scene/bodies[1]/inertia", "`hollow` is a sphere's");
  // A tensor's entries, named.
  check(
      [](BodySpec& b) {
        box(b);
        b.inertia_tensor = InertiaTensor{1, 1, 1, kNan, 0, 0};
      },
      "~scene/bodies[1]/inertia.ixy", "finite");
  check(
      [](BodySpec& b) {
        box(b);
        b.inertia_tensor = InertiaTensor{1, 1, 1, 0, 1, 0};
      },
      "~scene/bodies[1]/inertia.ixz", "not positive definite");
  check(
      [](BodySpec& b) {
        box(b);
        b.inertia_tensor = InertiaTensor{1, 1, 3, 0, 0, 0};
      },
      "~scene/bodies[1]/inertia", "triangle inequality");
  check(
      [](BodySpec& b) {
        box(b);
        b.inertia_tensor = InertiaTensor{0, 1, 1, 0, 0, 0};
      },
      "~scene/bodies[1]/inertia.ixx", "> 0");
  // Moments beyond the range of double.
  check(
      [](BodySpec& b) {
        box(b);
        b.size = V(1e160, 1e160, 1e160);
      },
      "~scene/bodies[1]/shape", "too large");
}

// The body's mass properties: its shape's closed form (a 0.1048 m cube of 0.37 kg: m s^2 / 6),
// or the tensor given, about the body's origin.
TEST(BodyShape, MassPropertiesAreTheShapesOrTheTensorGiven) {
  BodySpec cube = ball("cube", 0.37, 0.0, "m");
  box(cube);
  const auto uniform = bodyMassProperties(cube, "cube");
  ASSERT_TRUE(uniform.ok()) << uniform.error().message();
  const double moment = 0.37 * 0.1048 * 0.1048 / 6;
  EXPECT_NEAR((uniform->inertia - moment * Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 0,
              2 * std::numeric_limits<double>::epsilon() * moment);
  cube.inertia_tensor = InertiaTensor{1e-3, 2e-3, 2.5e-3, 1e-4, 0, 0};
  const auto given = bodyMassProperties(cube, "cube");
  ASSERT_TRUE(given.ok());
  EXPECT_EQ(given->inertia, cube.inertia_tensor->matrix());
  EXPECT_EQ(given->centre_of_mass, V::Zero());
  EXPECT_EQ(given->volume, uniform->volume);
}

TEST(BodyShape, ShapeNamesReadAndWrite) {
  for (const BodyShape shape : {BodyShape::kSphere, BodyShape::kBox, BodyShape::kCylinder,
                                BodyShape::kCapsule, BodyShape::kMesh}) {
    const auto parsed = parseBodyShape(toString(shape), "shape");
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, shape);
  }
  expectRefused(parseBodyShape("plane", "~scene/bodies[0]/shape").ok()
                    ? Status(Ok{})
                    : Status(parseBodyShape("plane", "~scene/bodies[0]/shape").error()),
                "~scene/bodies[0]/shape", "unknown body shape 'plane'");
}

}  // namespace
}  // namespace collision_response::core

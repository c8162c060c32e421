// Box2D 2.4 on the benchmark's planar scenes (only in the benchmark; the product never links it).
//
// A scene is planar when one axis carries no motion (every body's position and velocity, gravity
// and every plane's normal are zero along it, sphere obstacles sit at zero): the drop test
// (x-z), the cradle, the break (x-y), the fast ball, the long runs' bounce and chain. The gas is
// not: Box2D does not play it. Balls are circles on dynamic bodies (density m / (pi r^2), so
// that the mass is m), planes are two-sided b2EdgeShapes on a static body, moved back by the
// edge's skin b2_polygonRadius (2 b2_linearSlop = 1 cm, b2_common.h) so that the surface the
// balls meet is the plane; sphere obstacles static circles. One b2World::Step per state at the
// rate with 8 velocity and 3 position iterations ("The suggested iteration count for Box2D is
// 8 for velocity and 3 for position", Box2D manual, "Hello Box2D"). Sleeping off; friction 0.
//
// Restitution: each contact gets the scene's coefficient of its pair in PreSolve
// (b2Contact::SetRestitution: "Override the default mixed restitution", b2_contact.h; the default
// mix is the larger of the two fixtures'), and restitutionThreshold 0 on every fixture (2.4's
// per-fixture replacement of b2_velocityThreshold: "Collisions above this speed have restitution
// applied", b2_fixture.h; default 1 m/s). Every ball is a bullet (continuous collision against
// moving bodies as well as static ones, b2BodyDef::bullet). Limits Box2D sets: a body moves at
// most b2_maxTranslation = 2 m per step (b2_common.h), so faster than 2 m x rate is clipped;
// positions and velocities are floats.
#include <box2d/box2d.h>

#include <array>
#include <map>
#include <optional>

#include "harness.h"

namespace collision_response::bench {
namespace {

/// The two axes a planar scene moves in, or none.
std::optional<std::array<int, 2>> planeOf(const core::Scene& scene) {
  const V g = scene.effects.gravity ? scene.gravity : V::Zero();
  for (int dropped = 2; dropped >= 0; --dropped) {
    bool still = g[dropped] == 0;
    for (const core::BodySpec& body : scene.bodies) {
      still = still && body.position[dropped] == 0 && body.velocity[dropped] == 0;
    }
    for (const core::ObstacleSpec& obstacle : scene.obstacles) {
      still = still &&
              (obstacle.shape == core::ObstacleShape::kPlane ? obstacle.normal[dropped] == 0
                                                             : obstacle.position[dropped] == 0);
    }
    if (still) {
      std::array<int, 2> axes{};
      int next = 0;
      for (int axis = 0; axis < 3; ++axis) {
        if (axis != dropped) axes[static_cast<std::size_t>(next++)] = axis;
      }
      return axes;
    }
  }
  return std::nullopt;
}

/// Gives every contact the scene's coefficient of its two materials.
class PairRestitution : public b2ContactListener {
 public:
  explicit PairRestitution(const core::Scene& scene) : scene_(scene) {}
  void setMaterial(const b2Fixture* fixture, const std::string& material) {
    material_[fixture] = material;
  }
  void PreSolve(b2Contact* contact, const b2Manifold*) override {
    const double e = *scene_.materials.restitution(material_.at(contact->GetFixtureA()),
                                                   material_.at(contact->GetFixtureB()));
    contact->SetRestitution(static_cast<float>(e));
    contact->SetRestitutionThreshold(0.0f);
  }

 private:
  const core::Scene& scene_;
  std::map<const b2Fixture*, std::string> material_;
};

}  // namespace

Engine box2dEngine() {
  return [](const core::Scene& scene, const Play& play) {
    if (movesObstacles(play)) {
      Run run;
      run.unsupported = "no moving obstacles in this harness";
      return run;
    }
    Run run;
    const std::optional<std::array<int, 2>> plane = planeOf(scene);
    if (!plane) {
      run.unsupported = "not planar (Box2D is a 2D engine)";
      return run;
    }
    const int a = (*plane)[0], b = (*plane)[1];
    const auto in2d = [a, b](const V& v) {
      return b2Vec2(static_cast<float>(v[a]), static_cast<float>(v[b]));
    };
    const V g = scene.effects.gravity ? scene.gravity : V::Zero();
    b2World world(in2d(g));
    world.SetAllowSleeping(false);
    PairRestitution listener(scene);
    world.SetContactListener(&listener);

    std::vector<b2Body*> bodies;
    for (const core::BodySpec& spec : scene.bodies) {
      b2BodyDef definition;
      definition.type = b2_dynamicBody;
      definition.position = in2d(spec.position);
      definition.linearVelocity = in2d(spec.velocity);
      definition.bullet = true;
      definition.allowSleep = false;
      b2Body* body = world.CreateBody(&definition);
      b2CircleShape circle;
      circle.m_radius = static_cast<float>(spec.radius);
      b2FixtureDef fixture;
      fixture.shape = &circle;
      fixture.density =
          static_cast<float>(spec.mass / (3.14159265358979323846 * spec.radius * spec.radius));
      fixture.friction = 0.0f;
      fixture.restitutionThreshold = 0.0f;
      listener.setMaterial(body->CreateFixture(&fixture), spec.material);
      bodies.push_back(body);
    }
    b2BodyDef ground_definition;
    b2Body* ground = world.CreateBody(&ground_definition);
    for (const core::ObstacleSpec& spec : scene.obstacles) {
      b2FixtureDef fixture;
      fixture.friction = 0.0f;
      fixture.restitutionThreshold = 0.0f;
      b2EdgeShape edge;
      b2CircleShape circle;
      b2PolygonShape box;
      if (spec.shape == core::ObstacleShape::kPlane) {
        const V n = spec.normal.normalized();
        const b2Vec2 normal = in2d(n), along(-normal.y, normal.x);
        const b2Vec2 point = static_cast<float>(spec.offset - b2_polygonRadius) * normal;
        const float half_length = 100.0f;
        edge.SetTwoSided(point - half_length * along, point + half_length * along);
        fixture.shape = &edge;
      } else if (spec.shape == core::ObstacleShape::kBox) {
        // Along the axes, its skin (b2_polygonRadius) inside the scene's size.
        const b2Vec2 half = in2d(V(0.5 * spec.size));
        box.SetAsBox(half.x - b2_polygonRadius, half.y - b2_polygonRadius, in2d(spec.position),
                     0.0f);
        fixture.shape = &box;
      } else {
        circle.m_p = in2d(spec.position);
        circle.m_radius = static_cast<float>(spec.radius);
        fixture.shape = &circle;
      }
      listener.setMaterial(ground->CreateFixture(&fixture), spec.material);
    }

    const auto updates = static_cast<long>(std::llround(play.duration * play.rate));
    const double dt = 1.0 / play.rate;
    std::vector<V> positions(bodies.size(), V::Zero()), velocities(bodies.size(), V::Zero());
    for (long k = 0; k <= updates; ++k) {
      if (k > 0) world.Step(static_cast<float>(dt), 8, 3);
      for (std::size_t i = 0; i < bodies.size(); ++i) {
        const b2Vec2 p = bodies[i]->GetPosition(), v = bodies[i]->GetLinearVelocity();
        positions[i][a] = p.x;
        positions[i][b] = p.y;
        velocities[i][a] = v.x;
        velocities[i][b] = v.y;
      }
      run.record(play, static_cast<double>(k) * dt, positions, velocities);
    }
    return run;
  };
}

}  // namespace collision_response::bench

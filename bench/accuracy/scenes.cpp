#include <cmath>
#include <random>

#include "collision_response/core/triangle_mesh.h"
#include "harness.h"

namespace collision_response::bench {
namespace {

// Three draws for one vector, in a stated order. The arguments of one call are evaluated in an
// order the language leaves open (g++ right to left, clang left to right), so V(d(e), d(e), d(e))
// was another scene under each compiler; z, then y, then x is the order g++ gave them, which
// the trace digest (test/core/trace_digest.txt) and the references hold.
template <class Distribution>
V drawZyx(Distribution& distribution, std::mt19937_64& engine) {
  const double z = distribution(engine);
  const double y = distribution(engine);
  const double x = distribution(engine);
  return V(x, y, z);
}

/// The state rates of the short scenes (Hz).
const std::vector<double> kRates = {10.0, 30.0, 60.0, 100.0, 300.0, 1000.0};

core::BodySpec ball(const std::string& id, double mass, double radius, const std::string& material,
                    const V& position, const V& velocity = V::Zero()) {
  core::BodySpec body;
  body.id = id;
  body.mass = mass;
  body.radius = radius;
  body.material = material;
  body.position = position;
  body.velocity = velocity;
  return body;
}

core::ObstacleSpec plane(const std::string& id, const V& normal, double offset,
                         const std::string& material) {
  core::ObstacleSpec obstacle;
  obstacle.id = id;
  obstacle.normal = normal;
  obstacle.offset = offset;
  obstacle.material = material;
  return obstacle;
}

// The seed's drop test: one ball of each material 1 m above concrete, gravity on.
BenchScene dropTestScene() {
  BenchScene bench{"drop_test", {}, 2.5, kRates, false, true, {}};
  bench.stepped_rates = kRates;  // e from the bounce heights: what stepping costs
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  int i = 0;
  for (const core::SeedMeasurement& row : core::seedTable()) {
    scene.bodies.push_back(ball(row.material, 0.1, 0.03, row.material, V(0.3 * i++, 0, 1.03)));
  }
  scene.obstacles.push_back(plane("floor", V(0, 0, 1), 0.0, "concrete"));
  return bench;
}

// An idealised Newton's cradle: five touching balls (e = 1), the first 0.02 m away at 1 m/s.
BenchScene cradleScene() {
  BenchScene bench{"cradle", {}, 0.1, kRates, false, true, {}};
  core::Scene& scene = bench.scene;
  (void)scene.materials.addMaterial("polished_steel", core::Material{1.0, {}}, "m");
  scene.bodies.push_back(ball("ball_1", 0.26, 0.02, "polished_steel", V(-0.06, 0, 0), V(1, 0, 0)));
  for (int i = 2; i <= 5; ++i) {
    scene.bodies.push_back(
        ball("ball_" + std::to_string(i), 0.26, 0.02, "polished_steel", V(0.04 * (i - 2), 0, 0)));
  }
  return bench;
}

// The billiards break of config/scenes/billiards_break.yaml: the cue ball at 6 m/s into a rack
// of fifteen touching balls on a 2.54 m x 1.27 m table.
BenchScene breakScene() {
  BenchScene bench{"billiards_break", {}, 1.0, kRates, false, true, {"friction, spin"}};
  core::Scene& scene = bench.scene;
  (void)scene.materials.addMaterial("cushion", core::Material{0.75, {}}, "m");
  const double r = 0.028575;
  scene.bodies.push_back(ball("cue", 0.17, r, "billiard_ball", V(0.635, 0.635, 0), V(6, 0, 0)));
  int n = 1;
  for (int row = 0; row < 5; ++row) {
    for (int j = 0; j <= row; ++j) {
      char id[16];
      std::snprintf(id, sizeof id, "ball_%02d", n++);
      scene.bodies.push_back(
          ball(id, 0.17, r, "billiard_ball",
               V(1.905 + row * r * std::sqrt(3.0), 0.635 + (j - row / 2.0) * 2 * r, 0)));
    }
  }
  scene.obstacles.push_back(plane("cushion_head", V(1, 0, 0), 0.0, "cushion"));
  scene.obstacles.push_back(plane("cushion_foot", V(-1, 0, 0), -2.54, "cushion"));
  scene.obstacles.push_back(plane("cushion_right", V(0, 1, 0), 0.0, "cushion"));
  scene.obstacles.push_back(plane("cushion_left", V(0, -1, 0), -1.27, "cushion"));
  return bench;
}

// A fast ball (radius 0.02 m, 50 m/s) against a thin post (a fixed sphere of radius 0.01 m)
// 1 m ahead: 2.5 cm of travel per step at 2 kHz, half a metre at 100 Hz.
BenchScene tunnellingScene() {
  BenchScene bench{"tunnelling", {}, 0.1, kRates, false, true, {}};
  core::Scene& scene = bench.scene;
  (void)scene.materials.addMaterial("hard", core::Material{0.8, {}}, "m");
  scene.bodies.push_back(ball("bullet", 0.01, 0.02, "hard", V(0, 0, 0), V(50, 0, 0)));
  core::ObstacleSpec post;
  post.id = "post";
  post.shape = core::ObstacleShape::kSphere;
  post.radius = 0.01;
  post.position = V(1, 0, 0);
  post.material = "hard";
  scene.obstacles.push_back(post);
  return bench;
}

// 64 elastic balls in a closed 2 m box, random velocities up to 2 m/s: energy must stay.
BenchScene gasScene() {
  BenchScene bench{"sphere_gas", {}, 2.0, kRates, false, true, {"gravity"}, "conservation"};
  core::Scene& scene = bench.scene;
  (void)scene.materials.addMaterial("elastic", core::Material{1.0, {}}, "m");
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> speed(-2, 2);
  for (int i = 0; i < 64; ++i) {
    scene.bodies.push_back(
        ball("gas_" + std::to_string(100 + i), 0.1, 0.05, "elastic",
             V(0.25 + 0.5 * (i % 4), 0.25 + 0.5 * ((i / 4) % 4), 0.25 + 0.5 * (i / 16)),
             drawZyx(speed, engine)));
  }
  const V normals[] = {V(1, 0, 0), V(-1, 0, 0), V(0, 1, 0), V(0, -1, 0), V(0, 0, 1), V(0, 0, -1)};
  for (int i = 0; i < 6; ++i) {
    scene.obstacles.push_back(
        plane("wall_" + std::to_string(i), normals[i], i % 2 ? -2.0 : 0.0, "elastic"));
  }
  return bench;
}

// One ball (radius 0.03 m) dropped from 1 m onto a floor, e = `restitution`, threshold 0, until
// it has bounced 1,000 times or its bounces accumulate (e < 1: at t = sqrt(2h/g)(1 + e)/(1 - e)).
BenchScene bounceScene(const std::string& name, double restitution, double duration) {
  BenchScene bench{name, {}, duration, {100.0, 1000.0}, true, true, {}};
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  (void)scene.materials.addMaterial("ball", core::Material{restitution, {}}, "m");
  scene.bodies.push_back(ball("ball", 0.1, 0.03, "ball", V(0, 0, 1.03)));
  scene.obstacles.push_back(plane("floor", V(0, 0, 1), 0.0, "concrete"));
  return bench;
}

// The two-ball chain: a heavy ball (1 kg) at 1 m/s towards a light one (1/ratio kg) that rests
// between it and a wall, on one line, e = 1. The light ball shuttles between the two; the impacts
// end when both move away from the wall, after ceil(pi / atan(sqrt(m/M))) - 1 of them (3, 99 and
// 3141 for ratios 1, 1e3, 1e6: G. Galperin, "Playing pool with pi", Regular and Chaotic
// Dynamics 8 (2003)).
BenchScene chainScene(const std::string& name, double ratio) {
  BenchScene bench{name, {}, 3.0, {100.0, 1000.0}, true, true, {}};
  core::Scene& scene = bench.scene;
  (void)scene.materials.addMaterial("elastic", core::Material{1.0, {}}, "m");
  scene.bodies.push_back(ball("light", 1.0 / ratio, 0.05, "elastic", V(0.55, 0, 0)));
  scene.bodies.push_back(ball("heavy", 1.0, 0.05, "elastic", V(1.1, 0, 0), V(-1, 0, 0)));
  scene.obstacles.push_back(plane("wall", V(1, 0, 0), 0.0, "elastic"));
  return bench;
}

// Lasting contact (gravity): the material of every surface of these scenes, e = 0.3 (the bounces
// die out quickly), Coulomb mu = 1 where the friction effect is on.
constexpr double kLastingRestitution = 0.3;
constexpr double kLastingFriction = 1.0;
const char* const kLastingMaterial = "putty";

core::MaterialTable lastingMaterials() {
  core::MaterialTable materials = core::MaterialTable::seed();
  (void)materials.addMaterial(kLastingMaterial,
                              core::Material{kLastingRestitution, kLastingFriction}, "m");
  return materials;
}

// A ball (r = 0.05 m) released at rest on a 10-degree incline slides (frictionless; rolls with
// friction and spin) 0.2 m into a wall and comes to rest in the corner. The incline descends
// towards +x; the wall faces -x.
BenchScene ballCornerScene() {
  BenchScene bench{"ball_corner", {}, 2.0, kRates, false, true, {"friction, spin"}, "lasting"};
  bench.stepped_rates = kRates;
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  scene.materials = lastingMaterials();
  const double incline = 10.0 * M_PI / 180.0, r = 0.05, slide = 0.2;
  scene.bodies.push_back(ball("ball", 0.1, r, kLastingMaterial, V(0, 0, r / std::cos(incline))));
  scene.obstacles.push_back(
      plane("incline", V(std::sin(incline), 0, std::cos(incline)), 0.0, kLastingMaterial));
  scene.obstacles.push_back(
      plane("wall", V(-1, 0, 0), -(slide * std::cos(incline) + r), kLastingMaterial));
  return bench;
}

// A ball (r = 0.05 m) on top of a fixed sphere (R = 0.2 m) resting on the floor, nudged at
// 0.01 m/s: it leaves the sphere (frictionless: cos theta = 2/3 + v0^2 / 3 g (R + r)), falls to
// the floor and bounces away.
BenchScene ballOffSphereScene() {
  BenchScene bench{"ball_off_sphere", {}, 1.5, kRates, false, true, {"friction, spin"}, "lasting"};
  bench.stepped_rates = kRates;
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  scene.materials = lastingMaterials();
  const double r = 0.05, big = 0.2;
  scene.bodies.push_back(
      ball("ball", 0.1, r, kLastingMaterial, V(0, 0, 2 * big + r), V(0.01, 0, 0)));
  core::ObstacleSpec dome;
  dome.id = "dome";
  dome.shape = core::ObstacleShape::kSphere;
  dome.radius = big;
  dome.position = V(0, 0, big);
  dome.material = kLastingMaterial;
  scene.obstacles.push_back(dome);
  scene.obstacles.push_back(plane("floor", V(0, 0, 1), 0.0, kLastingMaterial));
  return bench;
}

// A ball (r = 0.05 m) sliding frictionless at v0 = 0.2 m/s along a box's top face (a table,
// 1 x 1 x 0.5 m, its top at z = 0, its edge at x = 0) from 5 cm before its edge: it pivots about
// the edge and leaves it where cos theta = (2 + v0^2 / (g r)) / 3, then flies on with the
// horizontal velocity sqrt(g r) cos^(3/2) theta; 0.8 s (no floor).
BenchScene ballOffEdgeScene() {
  BenchScene bench{"ball_off_edge", {}, 0.8, kRates, false, true, {}, "lasting"};
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  scene.materials = lastingMaterials();
  const double r = 0.05;
  scene.bodies.push_back(ball("ball", 0.1, r, kLastingMaterial, V(-0.05, 0, r), V(0.2, 0, 0)));
  core::ObstacleSpec table;
  table.id = "table";
  table.shape = core::ObstacleShape::kBox;
  table.size = V(1.0, 1.0, 0.5);
  table.position = V(-0.5, 0, -0.25);
  table.material = kLastingMaterial;
  scene.obstacles.push_back(table);
  return bench;
}

// A ball (r = 0.05 m) flying at 1 m/s along x into a paddle (a thin box, 0.02 x 0.3 x 0.3 m,
// its face 0.257 m ahead of the ball's surface) moving at -0.5 m/s towards it, no gravity: it
// leaves at v_p + e (v_p - v) = -0.5 - 1.5 e (e = 0.3: -0.95 m/s), 0.5 s. The paddle moves as a
// tf frame does for ours, as a kinematic body for the peers.
BenchScene ballOffMovingPaddleScene() {
  BenchScene bench{"ball_off_moving_paddle", {}, 0.5, kRates, false, true, {}, "lasting"};
  core::Scene& scene = bench.scene;
  scene.materials = lastingMaterials();
  scene.bodies.push_back(ball("ball", 0.057, 0.033, kLastingMaterial, V(0, 0, 0), V(1, 0, 0)));
  core::ObstacleSpec paddle;
  paddle.id = "paddle";
  paddle.shape = core::ObstacleShape::kBox;
  paddle.size = V(0.02, 0.3, 0.3);
  paddle.position = V(0.3, 0, 0);
  paddle.frame = "paddle_link";
  paddle.material = kLastingMaterial;
  scene.obstacles.push_back(paddle);
  bench.obstacle_velocities = {V(-0.5, 0, 0)};
  return bench;
}

// A ball (r = 0.05 m) sliding frictionless at (1.5, 0.9, 0) m/s across a floor that is a mesh of
// 8 x 8 squares of two triangles (2 m across, at z = 0), over its internal edges, for 1 s: as on
// the plane it tessellates, it stays at z = r at its velocity. An engine that tests each
// triangle alone bounces off internal edges ("ghost collisions").
BenchScene ballOnMeshFloorScene() {
  BenchScene bench{"ball_on_mesh_floor", {}, 1.0, kRates, false, true, {}, "lasting"};
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  scene.materials = lastingMaterials();
  const double r = 0.05;
  scene.bodies.push_back(ball("ball", 0.1, r, kLastingMaterial, V(-0.9, -0.7, r), V(1.5, 0.9, 0)));
  constexpr int n = 8;
  std::vector<V> vertices;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) vertices.emplace_back(0.25 * i - 1.0, 0.25 * j - 1.0, 0.0);
  }
  std::vector<core::TriangleMesh::Triangle> triangles;
  const auto at = [](int i, int j) { return static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.shape = core::ObstacleShape::kMesh;
  floor.mesh = *core::TriangleMesh::build(vertices, triangles, "floor");
  floor.material = kLastingMaterial;
  scene.obstacles.push_back(floor);
  return bench;
}

// Three balls (r = 0.05 m) stacked on a floor, centres at r, 3r, 5r: at rest, for 2 s.
BenchScene ballStackScene() {
  BenchScene bench{"ball_stack", {}, 2.0, kRates, false, true, {"friction, spin"}, "lasting"};
  bench.stepped_rates = kRates;
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  scene.materials = lastingMaterials();
  const double r = 0.05;
  for (int i = 0; i < 3; ++i) {
    scene.bodies.push_back(
        ball("ball_" + std::to_string(i), 0.1, r, kLastingMaterial, V(0, 0, (2 * i + 1) * r)));
  }
  scene.obstacles.push_back(plane("floor", V(0, 0, 1), 0.0, kLastingMaterial));
  return bench;
}

// `count` balls (r = 0.05 m, e = 0.5) dropped from a loose cubic lattice (0.12 m apart, offsets
// up to 5 mm) into a box of side 0.12 * ceil(cbrt(count)) + 0.1 m, settling for `duration` s.
BenchScene ballPileScene(int count, double duration) {
  BenchScene bench{
      "ball_pile_" + std::to_string(count), {}, duration, {100.0}, true, true, {}, "lasting"};
  core::Scene& scene = bench.scene;
  scene.effects.gravity = true;
  (void)scene.materials.addMaterial("pile", core::Material{0.5, {}}, "m");
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count))));
  const double spacing = 0.12, size = spacing * side + 0.1;
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> offset(-0.005, 0.005);
  for (int i = 0; i < count; ++i) {
    const V cell(i % side, (i / side) % side, i / (side * side));
    char id[16];
    std::snprintf(id, sizeof id, "ball_%04d", i);
    scene.bodies.push_back(ball(id, 0.1, 0.05, "pile",
                                V(0.11, 0.11, 0.11) + spacing * cell + drawZyx(offset, engine)));
  }
  const V normals[] = {V(1, 0, 0), V(-1, 0, 0), V(0, 1, 0), V(0, -1, 0), V(0, 0, 1), V(0, 0, -1)};
  for (int i = 0; i < 6; ++i) {
    scene.obstacles.push_back(
        plane("wall_" + std::to_string(i), normals[i], i % 2 ? -size : 0.0, "pile"));
  }
  return bench;
}

}  // namespace

std::vector<BenchScene> benchScenes() {
  std::vector<BenchScene> scenes = {dropTestScene(), cradleScene(), breakScene(), tunnellingScene(),
                                    gasScene()};
  // Lasting contact (gravity): a ball into a corner, a ball off a sphere, a stack of three.
  scenes.push_back(ballCornerScene());
  BenchScene off_sphere = ballOffSphereScene();
  // The curved contact's integrator: ours at 100 Hz at each tolerance (error against CPU).
  off_sphere.integration_tolerances = {1e-6, 1e-8, 1e-10, 1e-12};
  scenes.push_back(off_sphere);
  scenes.push_back(ballStackScene());
  scenes.push_back(ballOffEdgeScene());
  scenes.push_back(ballOnMeshFloorScene());
  scenes.push_back(ballOffMovingPaddleScene());
  // Long runs (restitution fidelity): 1,000 bounces; e < 1 stops where the bounces accumulate
  // (t = 0.4515 (1 + e) / (1 - e) s), half a second later; e = 1: after the 1,000th bounce's apex.
  scenes.push_back(bounceScene("bounce_e0.5", 0.5, 1.9));
  scenes.push_back(bounceScene("bounce_e0.9", 0.9, 9.1));
  scenes.push_back(bounceScene("bounce_e1", 1.0, 903.5));
  scenes.push_back(chainScene("chain_ratio_1", 1.0));
  scenes.push_back(chainScene("chain_ratio_1e3", 1e3));
  scenes.push_back(chainScene("chain_ratio_1e6", 1e6));
  BenchScene gas = gasScene();
  gas.name = "sphere_gas_60s";
  gas.duration = 60.0;
  gas.rates = {100.0, 1000.0};
  gas.long_run = true;
  gas.record_all = false;
  gas.effect_variants.clear();
  scenes.push_back(gas);
  // A pile settling in a box: a long run (once per setting), Bullet and ODE beside ours. Ours
  // steps the pile's dense clusters (stepped_cluster_min_bodies, 32 by default: the 27-ball pile
  // stays exact, and is stepped whole by "ours, stepped"); ODE's dWorldStep (28 s at 300, 0.5 s
  // at 100: its dense solve grows as the cube of the contacts) plays up to 100. Rates: the
  // stepped sub-step is each update's interval; 1000 Hz on the two small piles only (ours'
  // 1,000-ball pile at 300 Hz takes minutes already). The 100 balls again for 4 s: frictionless,
  // a pile is still rearranging at 2 s.
  for (const int count : {27, 100, 300, 1000}) {
    BenchScene pile = ballPileScene(count, 2.0);
    pile.engines = {"ours", "bullet", "ode"};
    pile.rates = {100.0, 300.0, 1000.0};
    if (count == 27) pile.stepped_rates = pile.rates;
    if (count >= 300) {
      pile.engines = {"ours", "bullet"};
      pile.rates = {100.0, 300.0};
    }
    scenes.push_back(pile);
    if (count == 100) {
      BenchScene longer = ballPileScene(count, 4.0);
      longer.name += "_4s";
      longer.engines = pile.engines;
      scenes.push_back(longer);
    }
  }
  return scenes;
}

core::Scene withEffects(const BenchScene& bench, const std::string& effects) {
  core::Scene scene = bench.scene;
  if (effects.find("friction") != std::string::npos) scene.effects.friction = true;
  if (effects.find("spin") != std::string::npos) scene.effects.spin = true;
  if (effects.find("gravity") != std::string::npos) scene.effects.gravity = true;
  return scene;
}

std::string referenceName(const BenchScene& bench, const std::string& effects) {
  if (effects == "none") return bench.name;
  std::string name = bench.name;
  for (const char* effect : {"gravity", "friction", "spin"}) {
    if (effects.find(effect) != std::string::npos) name += std::string("+") + effect;
  }
  return name;
}

}  // namespace collision_response::bench

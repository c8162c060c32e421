// What a tumbling body's certified first contact costs per query (geometry/tumbling_contact.h):
// a box with three different moments (its orientation by Jacobi's elliptic functions at each
// step) tossed spinning onto a floor, onto a fixed box, onto a tessellated floor mesh (20,000
// triangles) and against another tumbling box; a cube (isotropic: a fixed spin) onto the floor.
// The steps per query are reported beside the time. Google Benchmark; built on demand:
// cmake --build .ws/build --target bench_tumbling_contact.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "collision_response/core/triangle_mesh.h"
#include "geometry/tumbling_contact.h"

namespace collision_response::core {
namespace {

using V = Eigen::Vector3d;
const Eigen::Quaterniond kTurned = Eigen::Quaterniond(0.48, 0.64, 0.36, 0.48).normalized();

TumblingBody tossedBox(bool isotropic, const V& position = V(0, 0, 1)) {
  const V moments = isotropic ? V(1, 1, 1) : V(2, 3, 4);
  return TumblingBody::create(Cuboid{V(0.15, 0.1, 0.05)}, moments, 0.0, position, V(0.5, 0.2, 1.0),
                              V(0, 0, -9.81), kTurned, V(3, -5, 12))
      .value();
}

std::shared_ptr<const TriangleMesh> floorMesh() {
  // 100 x 100 squares of 4 cm, two triangles each, about the origin at z = 0.
  std::vector<Eigen::Vector3d> vertices;
  std::vector<TriangleMesh::Triangle> triangles;
  constexpr int n = 100;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) vertices.emplace_back(0.04 * (i - n / 2), 0.04 * (j - n / 2), 0);
  }
  const auto at = [](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return TriangleMesh::build(vertices, triangles, "floor").value();
}

void query(benchmark::State& state, const TumblingBody& body, const PlacedShape& obstacle) {
  int steps = 0, queries = 0;
  for (auto _ : state) {
    const FirstContactResult r = firstContact(body, obstacle, 0.0, 2.0);
    benchmark::DoNotOptimize(r.contact);
    steps += r.steps;
    ++queries;
  }
  state.counters["steps"] = static_cast<double>(steps) / queries;
}

void boxOntoFloor(benchmark::State& state) {
  PlacedShape floor;
  floor.shape = Plane{V::UnitZ(), 0.0};
  query(state, tossedBox(state.range(0) == 1), floor);
}

void boxOntoBox(benchmark::State& state) {
  PlacedShape table;
  table.shape = Cuboid{V(0.5, 0.5, 0.2)};
  table.pose.transform.translation() = V(0.3, 0, 0.2);
  query(state, tossedBox(false, V(0, 0, 1.4)), table);
}

void boxOntoFloorMesh(benchmark::State& state) {
  PlacedShape floor;
  floor.shape = Mesh{floorMesh()};
  query(state, tossedBox(false), floor);
}

void boxAgainstBox(benchmark::State& state) {
  const TumblingBody a = tossedBox(false);
  const TumblingBody b = TumblingBody::create(Cuboid{V(0.1, 0.1, 0.2)}, V(3, 2, 1.5), 0.0,
                                              V(0.6, 0.2, 1.3), V(-0.5, 0, 0.5), V(0, 0, -9.81),
                                              Eigen::Quaterniond::Identity(), V(-4, 2, 7))
                             .value();
  int steps = 0, queries = 0;
  for (auto _ : state) {
    const FirstContactResult r = firstContact(a, b, 0.0, 2.0);
    benchmark::DoNotOptimize(r.contact);
    steps += r.steps;
    ++queries;
  }
  state.counters["steps"] = static_cast<double>(steps) / queries;
}

// doc/performance.md's creep ("Worse where an impact is plastic"): a box of 0.12 x 0.10 x 0.08 m
// and 1 kg on its corner 5e-12 m above the floor, that corner straight below its centre, at rest
// but spinning at 37 rad/s about x (the corner moving sideways at 37 r = 3.2 m/s, r its distance
// from the centre, and lifted by its turning only), gravity on: its next contact, the next corner.
// Arg 1: a cube of 0.1 m in the same state (a fixed spin).
void creepingCorner(benchmark::State& state) {
  const bool cube = state.range(0) == 1;
  const V half = cube ? V(0.05, 0.05, 0.05) : V(0.06, 0.05, 0.04);
  const V sides = 2 * half;
  const V moments = V(sides.y() * sides.y() + sides.z() * sides.z(),
                      sides.x() * sides.x() + sides.z() * sides.z(),
                      sides.x() * sides.x() + sides.y() * sides.y()) /
                    12.0;
  // The corner -half turned straight down.
  const Eigen::Quaterniond down = Eigen::Quaterniond::FromTwoVectors(-half, -V::UnitZ());
  const TumblingBody body =
      TumblingBody::create(Cuboid{half}, moments, 0.0, V(0, 0, half.norm() + 5e-12), V::Zero(),
                           V(0, 0, -9.81), down, V(37, 0, 0))
          .value();
  PlacedShape floor;
  floor.shape = Plane{V::UnitZ(), 0.0};
  int steps = 0, queries = 0;
  double found = 0;
  for (auto _ : state) {
    const FirstContactResult r = firstContact(body, floor, 0.0, 0.1, {1e-12, 1e-12, 1e-9, 1 << 22});
    benchmark::DoNotOptimize(r.contact);
    steps += r.steps;
    ++queries;
    found = r.contact ? r.contact->time : -1.0;
  }
  state.counters["steps"] = static_cast<double>(steps) / queries;
  state.counters["contact_s"] = found;
}

BENCHMARK(boxOntoFloor)->Arg(0)->Arg(1);  // 0: asymmetric, 1: a cube (isotropic)
BENCHMARK(boxOntoBox);
BENCHMARK(boxOntoFloorMesh);
BENCHMARK(boxAgainstBox);
BENCHMARK(creepingCorner)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace collision_response::core

BENCHMARK_MAIN();

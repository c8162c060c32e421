// A fixed workload, for counting instructions (valgrind --tool=callgrind): with every effect off,
// built once against the core and once against the core compiled without effects, the two
// counts show what an effect that is off costs, free of timing noise; with effects named, the
// same workloads as bench_effects.cpp's with them on (doc/performance.md, what the solver body
// costs the balls).
//   effects_instructions impacts|updates [gravity] [friction] [spin] [drag] [magnus]
// impacts: 100,000 of a ball striking the floor (friction and spin only); updates: 200 state
// updates of 100 balls in a closed box.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "effects_workload.h"

int main(int argc, char** argv) {
  using namespace collision_response;
  const bool updates = argc > 1 && std::strcmp(argv[1], "updates") == 0;
  std::vector<std::string> effects;
  for (int i = 2; i < argc; ++i) {
    const std::string effect = argv[i];
    const bool known = effect == "gravity" || effect == "friction" || effect == "spin" ||
                       effect == "drag" || effect == "magnus";
    if (!known || (!updates && effect != "friction" && effect != "spin")) {
      std::fprintf(stderr,
                   "effect '%s' is not one of the workload's: impacts take friction and spin, "
                   "updates gravity, friction, spin, drag and magnus\n",
                   argv[i]);
      return 2;
    }
    effects.push_back(effect);
  }
  const auto on = [&](const char* effect) {
    for (const std::string& e : effects) {
      if (e == effect) return true;
    }
    return false;
  };
  std::size_t count = 0;
  if (updates) {
    bench::BoxRun run(on("gravity"), on("friction"), on("spin"), on("drag"), on("magnus"));
    for (int i = 0; i < 200; ++i) count += run.update();
  } else {
    const core::CollisionRequest request = bench::ballOnFloor(effects);
    const core::MaterialTable materials = core::MaterialTable::seed();
    for (int i = 0; i < 100000; ++i) count += core::computeCollision(request, materials).ok();
  }
  std::printf("%zu\n", count);
  return 0;
}

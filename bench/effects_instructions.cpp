// A fixed workload with every effect off, for counting instructions (valgrind --tool=callgrind):
// built once against the core and once against the core compiled without effects, the two
// counts show what an effect that is off costs, free of timing noise.
//   effects_instructions impacts|updates
#include <cstdio>
#include <cstring>

#include "effects_workload.h"

int main(int argc, char** argv) {
  using namespace collision_response;
  const bool updates = argc > 1 && std::strcmp(argv[1], "updates") == 0;
  std::size_t count = 0;
  if (updates) {
    bench::BoxRun run(false, false, false);
    for (int i = 0; i < 200; ++i) count += run.update();
  } else {
    const core::CollisionRequest request = bench::ballOnFloor({});
    const core::MaterialTable materials = core::MaterialTable::seed();
    for (int i = 0; i < 100000; ++i) count += core::computeCollision(request, materials).ok();
  }
  std::printf("%zu\n", count);
  return 0;
}

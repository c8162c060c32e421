// libFuzzer target: the monitor's update cycle (MonitorCycle: intake, time line, the monitor's
// step, the finiteness check of every impact) on a scene and a stream of messages made from the
// fuzzer's bytes: masses, radii, effects (drag and Magnus too), detection, obstacles, stepped
// clusters; ids (the scene's, unknown, empty, repeated), stamps (any seconds and nanoseconds, the
// clock's zero), frames, and every number of every state. Invariants:
//  - every impact in an update has only finite numbers; every report (a named drop or notice)
//    has a text, and a refused impact names its field;
//  - the work of one message is bounded: at most kAllocationCap bytes are allocated while it
//    is processed (the allocation cap: operator new counts), and no allocation is larger
//    (scripts/fuzz.sh also runs it with -malloc_limit_mb and -rss_limit_mb).
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <new>
#include <string>
#include <vector>

#include "collision_response/core/validation.h"
#include "collision_response/ros/monitor_cycle.h"
#include "fuzz_input.h"

using namespace collision_response;

namespace {

/// Bytes one message may have allocated while it is processed: far above what the largest
/// input here needs (a few hundred states), far below a runaway (the grid's once took GBs).
constexpr std::size_t kAllocationCap = std::size_t{64} << 20;

bool counting = false;
std::size_t allocated = 0;

void fail(const char* what) {
  std::fprintf(stderr, "invariant broken: %s\n", what);
  std::abort();
}

}  // namespace

void* operator new(std::size_t size) {
  if (counting) {
    allocated += size;
    if (allocated > kAllocationCap) {
      counting = false;
      fail("one message allocated more than the cap (unbounded work)");
    }
  }
  void* memory = std::malloc(size == 0 ? 1 : size);
  if (memory == nullptr) throw std::bad_alloc();
  return memory;
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return operator new(size);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return operator new(size, tag);
}
void operator delete(void* memory, const std::nothrow_t&) noexcept { std::free(memory); }
void operator delete[](void* memory, const std::nothrow_t&) noexcept { std::free(memory); }
void operator delete(void* memory) noexcept { std::free(memory); }
void operator delete[](void* memory) noexcept { std::free(memory); }
void operator delete(void* memory, std::size_t) noexcept { std::free(memory); }
void operator delete[](void* memory, std::size_t) noexcept { std::free(memory); }

namespace {

core::Scene makeScene(fuzz::FuzzInput& in) {
  core::Scene scene;
  const std::uint8_t flags = in.byte();
  scene.detection = flags & 1 ? core::Detection::kDiscrete : core::Detection::kContinuous;
  scene.effects.gravity = (flags & 2) != 0;
  scene.effects.friction = (flags & 4) != 0;
  scene.effects.spin = (flags & 8) != 0;
  if (flags & 16) scene.restitution_threshold = std::abs(in.number());
  const int bodies = 1 + in.byte() % 6;
  for (int i = 0; i < bodies; ++i) {
    core::BodySpec body;
    body.id = "b" + std::to_string(i);
    body.mass = in.byte() % 8 == 0 ? core::kImmovableMass : std::abs(in.number());
    body.radius = std::abs(in.number());
    body.material = core::seedTable()[in.byte() % core::seedTable().size()].material;
    const std::uint8_t shape = in.byte();
    body.inertia = shape % 2 ? core::Inertia::kSolid : core::Inertia::kHollow;
    if (i == 0) {
      // The first body's byte carries the air's effects in its upper bits (older inputs, whose
      // bits there were unused, decode as before).
      scene.effects.drag = (shape & 2) != 0;
      scene.effects.magnus = (shape & 4) != 0 && scene.effects.spin;
      scene.air_density = (shape & 8) != 0 ? 1e3 : core::kDefaultAirDensity;  // a liquid too
    }
    scene.bodies.push_back(body);
  }
  if (flags & 32) {
    core::ObstacleSpec plane;
    plane.id = "floor";
    plane.material = "concrete";
    for (int i = 0; i < 3; ++i) plane.normal[i] = in.number();
    plane.offset = in.number();
    scene.obstacles.push_back(plane);
  }
  if (flags & 64) {
    core::ObstacleSpec sphere;
    sphere.id = "post";
    sphere.shape = core::ObstacleShape::kSphere;
    sphere.material = "wooden_ball";
    for (int i = 0; i < 3; ++i) sphere.position[i] = in.number();
    sphere.radius = std::abs(in.number());
    scene.obstacles.push_back(sphere);
  }
  if (flags & 128) {
    // Stepped clusters of one to three bodies (doc/model.md, "Lasting contact"): the fuzzed
    // numbers reach the sub-step's solve.
    scene.stepped_cluster_min_bodies = 1 + in.byte() % 3;
    scene.stepped_cluster_time_step = 1e-4 + in.byte() / 255.0 * 0.05;
  }
  return scene;
}

BodyState makeState(fuzz::FuzzInput& in, const core::Scene& scene, const ros::Time& base) {
  BodyState state;
  const std::uint8_t which = in.byte();
  state.id = which < 200 ? scene.bodies[which % scene.bodies.size()].id
                         : (which < 230 ? "ghost" : std::string());
  const std::uint8_t stamp_kind = in.byte();
  if (stamp_kind < 200) {  // near the stream's base: the ordinary case
    state.header.stamp = base + ros::Duration(0, static_cast<std::int32_t>(in.byte()) * 1000000);
  } else {  // anything a publisher can write
    state.header.stamp.sec =
        static_cast<std::uint32_t>(in.byte()) << 24 | in.byte() << 16 | in.byte() << 8 | in.byte();
    state.header.stamp.nsec = (static_cast<std::uint32_t>(in.byte()) << 8 | in.byte()) * 15259;
  }
  state.header.frame_id = in.byte() < 240 ? "world" : "elsewhere";
  state.pose.position.x = in.number();
  state.pose.position.y = in.number();
  state.pose.position.z = in.number();
  state.pose.orientation.w = in.byte() < 250 ? 1.0 : in.number();
  state.twist.linear.x = in.number();
  state.twist.linear.y = in.number();
  state.twist.linear.z = in.number();
  if (scene.effects.spin) {
    state.twist.angular.x = in.number();
    state.twist.angular.y = in.number();
    state.twist.angular.z = in.number();
  }
  return state;
}

bool finite(const Impact& impact) {
  const auto twist = [](const geometry_msgs::Twist& t) {
    return std::isfinite(t.linear.x) && std::isfinite(t.linear.y) && std::isfinite(t.linear.z) &&
           std::isfinite(t.angular.x) && std::isfinite(t.angular.y) && std::isfinite(t.angular.z);
  };
  return std::isfinite(impact.contact_point.x) && std::isfinite(impact.contact_point.y) &&
         std::isfinite(impact.contact_point.z) && std::isfinite(impact.normal.x) &&
         std::isfinite(impact.normal.y) && std::isfinite(impact.normal.z) &&
         std::isfinite(impact.restitution) && std::isfinite(impact.impulse) &&
         std::isfinite(impact.friction_impulse) && std::isfinite(impact.energy_lost) &&
         twist(impact.velocity_a_before) && twist(impact.velocity_a_after) &&
         twist(impact.velocity_b_before) && twist(impact.velocity_b_after);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::FuzzInput in(data, size);
  core::Scene scene = makeScene(in);
  if (!core::validateScene(scene, "scene")) return 0;  // the loader refuses it, by name
  core::normalizePlanes(scene);
  MonitorParams params;
  params.contact_tolerance = in.byte() % 2 ? 1e-9 : in.byte() / 256.0;
  MonitorCycle cycle(scene, params);
  tf2::BufferCore tf;
  const ros::Time clock(1000, 0);
  ros::Time base(1000, 0);
  std::deque<std::vector<BodyState>> inputs;
  const int messages = 1 + in.byte() % 16;
  for (int m = 0; m < messages; ++m) {
    base += ros::Duration(0, static_cast<std::int32_t>(in.byte()) * 4000000);
    std::vector<BodyState> states(in.byte() % 12);
    for (BodyState& state : states) state = makeState(in, scene, base);
    inputs.push_back(std::move(states));
    MonitorCycle::Input input{&inputs.back(), in.byte() % 2 ? "/body_states" : "/other",
                              in.byte() % 2 ? "/one" : "/two", ""};
    allocated = 0;
    counting = true;
    const MonitorCycle::Update update =
        cycle.process(input, in.byte() < 16 ? ros::Time() : clock, false, tf);
    counting = false;
    for (const Impact& impact : update.impacts.impacts) {
      if (!finite(impact)) fail("a non-finite number in a published impact");
    }
    for (const Report& report : update.reports) {
      if (report.text.empty()) fail("a report without a text");
      if (report.reason == Reason::kImpactNotFinite &&
          report.text.find(core::kBeyondDoubles) == std::string::npos &&
          report.text.find("header.stamp") == std::string::npos) {
        fail("a refused impact that does not name its field");
      }
    }
    if (!std::isfinite(cycle.monitor().now())) fail("the monitor's time is not finite");
  }
  return 0;
}

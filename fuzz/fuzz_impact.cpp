// libFuzzer target: one collision through the core's service path (computeCollision), any
// inputs. Invariants:
//  - finite or not, every input gives either a named error or an answer with finite numbers;
//  - energy lost >= 0, and kinetic energy (linear and rotational, summed in long double) never
//    increases (an immovable body does not spin here: a driven wheel may hand energy over);
//  - with finite masses, momentum conserved within 8 ulps of sum m |v|, plus what the doubles
//    cannot hold: a velocity change below the smallest double (a body 1e450 times heavier than
//    the other) is lost whatever the formula, m times the smallest subnormal per component.
#include <cstdio>
#include <cstdlib>

#include "collision_response/core/collision.h"
#include "fuzz_input.h"

using namespace collision_response;

namespace {

void fail(const char* what) {
  std::fprintf(stderr, "invariant broken: %s\n", what);
  std::abort();
}

long double kineticEnergy(const core::Body& body, const Eigen::Vector3d& v,
                          const Eigen::Vector3d& w) {
  if (std::isinf(body.mass)) return 0.0L;
  const long double k = body.inertia == core::Inertia::kSolid ? 0.4L : 2.0L / 3.0L;
  return 0.5L * body.mass * v.cast<long double>().squaredNorm() +
         0.5L * k * body.mass * body.radius * body.radius * w.cast<long double>().squaredNorm();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::FuzzInput in(data, size);
  core::CollisionRequest request;
  for (core::Body* body : {&request.a, &request.b}) {
    body->mass = (in.byte() % 8 == 0) ? core::kImmovableMass : in.number();
    body->radius = in.number();
    body->inertia = in.byte() % 2 ? core::Inertia::kSolid : core::Inertia::kHollow;
    for (int i = 0; i < 3; ++i) body->position[i] = in.number();
    for (int i = 0; i < 3; ++i) body->velocity[i] = in.number();
    for (int i = 0; i < 3; ++i) body->angular_velocity[i] = in.number();
  }
  if (in.byte() % 2) {
    for (int i = 0; i < 3; ++i) request.normal[i] = in.number();
  }
  request.restitution = in.byte() % 4 == 0 ? in.number() : (in.byte() / 255.0);
  const std::uint8_t effects = in.byte();
  if (effects & 1) request.effects.push_back("friction");
  if (effects & 2) request.effects.push_back("spin");
  if (effects & 1) request.friction = in.byte() % 4 == 0 ? in.number() : in.byte() / 64.0;
  if (std::isinf(request.b.mass)) request.b.angular_velocity.setZero();
  if (std::isinf(request.a.mass)) request.a.angular_velocity.setZero();

  const auto outcome = core::computeCollision(request, core::MaterialTable::seed());
  if (!outcome) {
    if (outcome.error().field.empty() || outcome.error().reason.empty()) fail("unnamed error");
    return 0;
  }
  const core::CollisionOutcome& o = *outcome;
  if (!o.impact.velocity_a.allFinite() || !o.impact.velocity_b.allFinite() ||
      !o.angular_velocity_a.allFinite() || !o.angular_velocity_b.allFinite() ||
      !std::isfinite(o.impact.normal_impulse) || !std::isfinite(o.impact.energy_lost) ||
      !std::isfinite(o.friction_impulse)) {
    fail("a non-finite number in an answer");
  }
  if (o.impact.energy_lost < 0) fail("negative energy lost");
  constexpr long double kEps = std::numeric_limits<double>::epsilon();
  // In the rest frame of an immovable body, if there is one.
  const Eigen::Vector3d frame = std::isinf(request.b.mass)   ? request.b.velocity
                                : std::isinf(request.a.mass) ? request.a.velocity
                                                             : Eigen::Vector3d::Zero();
  const long double before =
      kineticEnergy(request.a, request.a.velocity - frame, request.a.angular_velocity) +
      kineticEnergy(request.b, request.b.velocity - frame, request.b.angular_velocity);
  const long double after =
      kineticEnergy(request.a, o.impact.velocity_a - frame, o.angular_velocity_a) +
      kineticEnergy(request.b, o.impact.velocity_b - frame, o.angular_velocity_b);
  // The velocities are doubles in the world frame: each component is rounded to eps of its
  // world-frame size, which in the rest frame of a moving immovable body is an energy of
  // m |v - frame| eps (|v| + |frame|) a body, however small the relative motion (a body at
  // 0.06 m/s against a wall moving at 10 m/s).
  long double rounding = 0;
  for (const auto* body : {&request.a, &request.b}) {
    if (std::isinf(body->mass)) continue;
    const Eigen::Vector3d& after_velocity =
        body == &request.a ? o.impact.velocity_a : o.impact.velocity_b;
    rounding += body->mass * static_cast<long double>((after_velocity - frame).norm()) * kEps *
                static_cast<long double>(after_velocity.norm() + frame.norm());
  }
  if (after > before * (1 + 256 * kEps) + 8 * rounding + 1e-300L) fail("kinetic energy increased");
  if (std::isfinite(request.a.mass) && std::isfinite(request.b.mass)) {
    const long double ma = request.a.mass, mb = request.b.mass;
    for (int i = 0; i < 3; ++i) {
      const long double p0 = ma * request.a.velocity[i] + mb * request.b.velocity[i];
      const long double p1 = ma * o.impact.velocity_a[i] + mb * o.impact.velocity_b[i];
      const long double scale = ma * (request.a.velocity.cast<long double>().norm() +
                                      o.impact.velocity_a.cast<long double>().norm()) +
                                mb * (request.b.velocity.cast<long double>().norm() +
                                      o.impact.velocity_b.cast<long double>().norm());
      const long double unrepresentable = (ma + mb) * 4 * std::numeric_limits<double>::denorm_min();
      if (std::abs(p1 - p0) > 8 * kEps * scale + unrepresentable) fail("momentum not conserved");
    }
  }
  return 0;
}

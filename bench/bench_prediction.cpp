// What a prediction's accuracy costs (README, "Prediction"): predictImpacts on a table-tennis
// serve through air (gravity, quadratic drag, Magnus; frictionless bounces, e = 0.9) at several
// integrator tolerances, against the serve's independent 40-digit reference
// (bench/accuracy/reference/serve_reference.txt, written by serve_reference.py beside it, whose
// header gives the model), beside Bullet and ODE (each optional) stepping the same serve forward
// at several rates; and the CPU of a gravity-only query of 10 bounces.
//   BM_PredictGravityTenBounces        10 bounces on a floor, gravity only
//   BM_PredictServe/<tolerance>        the serve over 1 s with the crossing of the plane x = 1.6
//   BM_PredictServeBounces/<tolerance> the same query without the plane (its bounces only)
//   BM_BulletServe/<rate>, BM_OdeServe/<rate>  the serve stepped to its second bounce
// Every benchmark writes its errors and its CPU per query (us_per_query) as counters, so that
// --benchmark_format=json carries them; scripts/accuracy.sh --prediction runs it and makes
// doc/prediction.md and doc/prediction.png (scripts/prediction_report.py).
//   bench_prediction [Google Benchmark flags]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "accuracy/reference/serve_reference.h"
#include "collision_response/core/prediction.h"
#ifdef COLLISION_RESPONSE_WITH_BULLET
#include <btBulletDynamicsCommon.h>

#include <memory>
#endif
#ifdef COLLISION_RESPONSE_WITH_ODE
#include <ode/ode.h>
#endif

namespace collision_response::bench {
namespace {

using V = Eigen::Vector3d;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

// The serve's model, as serve_reference.py states it.
constexpr double kG = 9.81;       // m/s^2
constexpr double kMass = 0.0027;  // kg
constexpr double kRadius = 0.02;  // m
constexpr double kDragCoefficient = 0.5;
constexpr double kLiftCoefficient = 0.2;
constexpr double kAirDensity = 1.2;   // kg/m^3
constexpr double kRestitution = 0.9;  // the ball on the table top
constexpr double kPlaneX = 1.6;       // m: the plane crossed after the second bounce
constexpr double kHorizon = 1.0;      // s: the query's horizon
const V kTableCentre(0, 0, 0.745);
const V kTableSize(2.74, 1.525, 0.03);

const ServeReference& reference() {
  static const ServeReference read = ServeReference::read(COLLISION_RESPONSE_SERVE_REFERENCE);
  return read;
}

/// An engine's answer at the second bounce (centre and velocity just after it) and at the
/// crossing of the plane x = kPlaneX.
struct ServeAnswer {
  double bounce_time = kNaN;
  V bounce_position = V::Constant(kNaN);
  V bounce_velocity_after = V::Constant(kNaN);
  V crossing_position = V::Constant(kNaN);
  /// The peers: the first bounce's coefficient as stepped, the vertical velocity of the step
  /// after it over that of the step before (the reference: 0.9).
  double bounce1_restitution = kNaN;
};

/// The answer's errors against the reference, as counters: the second bounce's instant (s),
/// its centre (m), the velocity after it (m/s), the centre at the plane's crossing (m; when
/// measured).
void setErrorCounters(benchmark::State& state, const ServeAnswer& answer) {
  const ServeReference& ref = reference();
  state.counters["bounce2_time_error"] = std::abs(answer.bounce_time - ref.value("bounce2_time"));
  state.counters["bounce2_position_error"] =
      (answer.bounce_position - ref.vector("bounce2_position")).norm();
  state.counters["bounce2_velocity_error"] =
      (answer.bounce_velocity_after - ref.vector("bounce2_velocity_after")).norm();
  if (!std::isnan(answer.crossing_position.x())) {
    state.counters["crossing_position_error"] =
        (answer.crossing_position - ref.vector("crossing_position")).norm();
  }
}

/// Runs `query` once per iteration, and writes its CPU time per iteration (this thread's CPU
/// clock over the loop) in microseconds as the counter us_per_query.
template <typename Query>
void timeQueries(benchmark::State& state, Query&& query) {
  timespec start{}, stop{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &start);
  for (auto _ : state) {
    auto answer = query();
    benchmark::DoNotOptimize(answer);
  }
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &stop);
  const double seconds = static_cast<double>(stop.tv_sec - start.tv_sec) +
                         1e-9 * static_cast<double>(stop.tv_nsec - start.tv_nsec);
  state.counters["us_per_query"] = 1e6 * seconds / static_cast<double>(state.iterations());
}

core::BodySpec servedBall() {
  core::BodySpec body;
  body.id = "ball";
  body.mass = kMass;
  body.radius = kRadius;
  body.material = "celluloid";
  body.inertia = core::Inertia::kHollow;
  body.drag_coefficient = kDragCoefficient;
  body.lift_coefficient = kLiftCoefficient;
  return body;
}

/// The ball ("celluloid", e = 0.9 against "concrete") over a concrete floor z = 0, under gravity.
core::Scene ballOverFloor() {
  core::Scene scene;
  scene.effects.gravity = true;
  scene.gravity = V(0, 0, -kG);
  const core::Status added =
      scene.materials.addMaterial("celluloid", core::Material{kRestitution, {}}, "celluloid");
  if (!added.ok()) throw std::runtime_error(added.error().message());
  scene.bodies = {servedBall()};
  core::ObstacleSpec floor;
  floor.id = "floor";
  floor.material = "concrete";
  scene.obstacles = {floor};
  return scene;
}

/// The serve's scene: the ball over the floor and a concrete table (a box whose top face is
/// z = 0.76); gravity, spin, drag and Magnus, no friction (the bounces are frictionless, so the
/// spin never changes).
core::Scene serveScene(double tolerance) {
  core::Scene scene = ballOverFloor();
  scene.effects.spin = true;
  scene.effects.drag = true;
  scene.effects.magnus = true;
  scene.air_density = kAirDensity;
  scene.flight_integration_tolerance = tolerance;
  core::ObstacleSpec table;
  table.id = "table";
  table.shape = core::ObstacleShape::kBox;
  table.position = kTableCentre;
  table.size = kTableSize;
  table.material = "concrete";
  scene.obstacles.push_back(table);
  return scene;
}

/// The serve's query: from the reference's initial state, over kHorizon, up to 10 impacts, with
/// the first crossing of the plane x = kPlaneX.
core::PredictionRequest serveRequest(const core::Scene& scene, double horizon = kHorizon) {
  const ServeReference& ref = reference();
  core::PredictionRequest request;
  request.body = scene.bodies[0];
  request.state.position = ref.vector("initial_position");
  request.state.velocity = ref.vector("initial_velocity");
  request.state.angular_velocity = ref.vector("angular_velocity");
  request.horizon = horizon;
  request.max_impacts = 10;
  request.effects = scene.effects;
  request.crossing = core::Plane{V::UnitX(), kPlaneX};
  return request;
}

/// One query, checked: it must find the two bounces on the table and the crossing.
core::Prediction predictServe(const core::Scene& scene, const core::PredictionRequest& request) {
  auto prediction = core::predictImpacts(scene, nullptr, core::MonitorSettings{}, request);
  if (!prediction.ok()) throw std::runtime_error(prediction.error().message());
  if (prediction->impacts.size() < 2) throw std::runtime_error("fewer than two bounces");
  for (std::size_t i = 0; i < 2; ++i) {
    if (prediction->model->obstacle(prediction->impacts[i].other).id != "table") {
      throw std::runtime_error("a bounce off something else than the table");
    }
  }
  return std::move(*prediction);
}

/// The serve over kHorizon at `tolerance`; `crossing`: with the plane's crossing asked for (the
/// whole query), otherwise its bounces only (the same query without the plane).
void BM_PredictServe(benchmark::State& state, double tolerance, bool crossing) {
  ServeAnswer answer;
  core::Scene scene;
  core::PredictionRequest request;
  try {
    scene = serveScene(tolerance);
    request = serveRequest(scene);
    if (!crossing) request.crossing.reset();
    const core::Prediction prediction = predictServe(scene, request);
    const core::ImpactRecord& bounce = prediction.impacts[1];
    answer.bounce_time = bounce.time;
    answer.bounce_position = bounce.contact_point - kRadius * bounce.normal;
    answer.bounce_velocity_after = bounce.velocity_a_after;
    if (crossing) {
      if (!prediction.crossing) throw std::runtime_error("no crossing of the plane");
      answer.crossing_position = prediction.crossing->position;
    }
  } catch (const std::exception& error) {
    state.SkipWithError(error.what());
    return;
  }
  timeQueries(state, [&] {
    return core::predictImpacts(scene, nullptr, core::MonitorSettings{}, request);
  });
  setErrorCounters(state, answer);
  state.counters["tolerance"] = tolerance;
}

// Gravity only: a ball (e = 0.9) thrown level at 0.5 m/s from 1 m over a floor, 10 impacts
// asked for (it makes them within 5.4 s; the horizon is 10 s). The 10th impact's instant against
// the closed form: falling h = 1 - r takes sqrt(2 h / g) and arrives at u = sqrt(2 g h); flight
// k (after impact k) lasts 2 e^k u / g.
void BM_PredictGravityTenBounces(benchmark::State& state) {
  core::Scene scene;
  try {
    scene = ballOverFloor();
  } catch (const std::exception& error) {
    state.SkipWithError(error.what());
    return;
  }
  core::PredictionRequest request;
  request.body = scene.bodies[0];
  request.state.position = V(0, 0, 1.0);
  request.state.velocity = V(0.5, 0, 0);
  request.horizon = 10.0;
  request.max_impacts = 10;
  request.effects = scene.effects;
  const auto first = core::predictImpacts(scene, nullptr, core::MonitorSettings{}, request);
  if (!first.ok() || first->impacts.size() != 10) {
    state.SkipWithError(first.ok() ? "not 10 impacts" : first.error().message().c_str());
    return;
  }
  const double h = 1.0 - kRadius, u = std::sqrt(2 * kG * h);
  double tenth = std::sqrt(2 * h / kG);
  for (int k = 1; k < 10; ++k) tenth += 2 * std::pow(kRestitution, k) * u / kG;
  timeQueries(state, [&] {
    return core::predictImpacts(scene, nullptr, core::MonitorSettings{}, request);
  });
  state.counters["bounce10_time_error"] = std::abs(first->impacts[9].time - tenth);
}

// --- the peers: Bullet and ODE stepping the serve forward ---------------------------------------
// Neither has quadratic drag or the Magnus force. Their nearest stand-in for drag is linear
// damping, a drag -c v. It is chosen to match the quadratic drag k |v| v at the serve's mean
// speed:  c = k v_mean,  k = rho C_d A / (2 m)  (A = pi r^2; k = 0.1396 1/m), v_mean the time
// average of |v| from the serve to its second bounce (taken from our prediction's samples at
// tolerance 1e-12, which agrees with the reference within 1e-9 m). Magnus has no stand-in: the
// peers fly the serve without its topspin's downward force (about 0.9 m/s^2 at 4 m/s, a tenth
// of gravity), so their error does not fall below that model error at any rate.

#if defined(COLLISION_RESPONSE_WITH_BULLET) || defined(COLLISION_RESPONSE_WITH_ODE)

double dampingRate() {
  static const double c = [] {
    const core::Scene scene = serveScene(1e-12);
    core::PredictionRequest request = serveRequest(scene, reference().value("bounce2_time"));
    request.sample_period = 1e-4;
    const core::Prediction prediction = predictServe(scene, request);
    double integral = 0;
    const std::vector<core::BodyStateSample>& s = prediction.samples;
    for (std::size_t i = 1; i < s.size(); ++i) {
      integral +=
          0.5 * (s[i].velocity.norm() + s[i - 1].velocity.norm()) * (s[i].time - s[i - 1].time);
    }
    const double mean_speed = integral / (s.back().time - s.front().time);
    const double k = kAirDensity * kDragCoefficient * kPi * kRadius * kRadius / (2 * kMass);
    return k * mean_speed;
  }();
  return c;
}

/// Steps a peer at `rate` from the serve's initial state: `step` advances it by 1 / rate and
/// returns its centre and velocity. The second bounce is the second step after which the
/// vertical velocity has turned from negative (or zero) to positive: the step's end is taken as
/// its instant, its state as the bounce's centre and velocity after, as the accuracy harness
/// measures the peers (bench/accuracy/measure.cpp). `to_crossing`: then on to the plane
/// x = kPlaneX, its crossing interpolated linearly between the two steps around it.
template <typename Step>
ServeAnswer stepServe(double rate, bool to_crossing, Step&& step) {
  const ServeReference& ref = reference();
  ServeAnswer answer;
  V position = ref.vector("initial_position"), velocity = ref.vector("initial_velocity");
  int bounces = 0;
  const auto steps = static_cast<long>(std::lround(2.0 * rate));  // 2 s at most
  for (long k = 1; k <= steps; ++k) {
    const auto [p, v] = step();
    if (velocity.z() <= 0 && v.z() > 0) {  // a bounce
      ++bounces;
      if (bounces == 1) answer.bounce1_restitution = -v.z() / velocity.z();
      if (bounces == 2) {
        answer.bounce_time = static_cast<double>(k) / rate;
        answer.bounce_position = p;
        answer.bounce_velocity_after = v;
        if (!to_crossing) return answer;
      }
    }
    if (bounces >= 2 && position.x() < kPlaneX && p.x() >= kPlaneX) {
      answer.crossing_position =
          position + (kPlaneX - position.x()) / (p.x() - position.x()) * (p - position);
      return answer;
    }
    position = p;
    velocity = v;
  }
  return answer;
}

/// Times `serve(false)` (one whole serve to its second bounce, the world built and torn down
/// within it), and counts the errors of `serve(true)`.
template <typename Serve>
void timePeer(benchmark::State& state, double rate, Serve&& serve) {
  ServeAnswer answer;
  try {
    answer = serve(true);
  } catch (const std::exception& error) {
    state.SkipWithError(error.what());
    return;
  }
  if (std::isnan(answer.bounce_time)) {
    state.SkipWithError("no second bounce within 2 s");
    return;
  }
  timeQueries(state, [&] { return serve(false); });
  setErrorCounters(state, answer);
  state.counters["rate"] = rate;
  state.counters["bounce1_restitution"] = answer.bounce1_restitution;
  state.counters["damping_rate"] = dampingRate();
}

#endif

#ifdef COLLISION_RESPONSE_WITH_BULLET

// Debian's Bullet is built in single precision: btScalar is float.
btScalar bt(double value) { return static_cast<btScalar>(value); }
btVector3 bt(const V& v) { return btVector3(bt(v.x()), bt(v.y()), bt(v.z())); }
V eigen(const btVector3& v) { return V(v.x(), v.y(), v.z()); }

/// Bullet as the accuracy harness sets it up for bouncing (bench/accuracy/bullet.cpp, its
/// maintainers' recommended settings: restitution at any speed, no warm starting, split impulse,
/// CCD on): the ball's restitution 0.9 and the table's and the floor's 1 (Bullet multiplies
/// the two), no friction. Bullet's linear damping d scales the velocity by (1 - d)^dt each step
/// (btRigidBody::applyDamping): d = 1 - exp(-c) makes that exp(-c dt), the linear drag's decay.
ServeAnswer bulletServe(double rate, bool to_crossing) {
  const ServeReference& ref = reference();
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
  world.setGravity(btVector3(0, 0, bt(-kG)));
  btContactSolverInfo& info = world.getSolverInfo();
  info.m_restitutionVelocityThreshold = 0;
  info.m_solverMode &= ~SOLVER_USE_WARMSTARTING;
  info.m_splitImpulse = 1;

  btSphereShape ball_shape(bt(kRadius));
  btVector3 inertia(0, 0, 0);
  ball_shape.calculateLocalInertia(bt(kMass), inertia);
  btTransform start;
  start.setIdentity();
  start.setOrigin(bt(ref.vector("initial_position")));
  btDefaultMotionState ball_motion(start);
  btRigidBody::btRigidBodyConstructionInfo ball_info(bt(kMass), &ball_motion, &ball_shape, inertia);
  ball_info.m_restitution = bt(kRestitution);
  ball_info.m_friction = 0;
  ball_info.m_rollingFriction = 0;
  ball_info.m_linearDamping = bt(1 - std::exp(-dampingRate()));
  ball_info.m_angularDamping = 0;
  btRigidBody ball(ball_info);
  ball.setLinearVelocity(bt(ref.vector("initial_velocity")));
  ball.setAngularVelocity(bt(ref.vector("angular_velocity")));
  ball.setActivationState(DISABLE_DEACTIVATION);
  ball.setCcdMotionThreshold(bt(kRadius));
  ball.setCcdSweptSphereRadius(bt(0.5 * kRadius));
  world.addRigidBody(&ball);

  btStaticPlaneShape floor_shape(btVector3(0, 0, 1), 0);
  btBoxShape table_shape(bt(V(0.5 * kTableSize)));
  table_shape.setMargin(0);
  btTransform table_pose;
  table_pose.setIdentity();
  table_pose.setOrigin(bt(kTableCentre));
  btTransform identity;
  identity.setIdentity();
  btDefaultMotionState floor_motion(identity), table_motion(table_pose);
  btRigidBody::btRigidBodyConstructionInfo floor_info(0, &floor_motion, &floor_shape);
  btRigidBody::btRigidBodyConstructionInfo table_info(0, &table_motion, &table_shape);
  floor_info.m_restitution = table_info.m_restitution = 1;
  floor_info.m_friction = table_info.m_friction = 0;
  btRigidBody floor(floor_info), table(table_info);
  world.addRigidBody(&floor);
  world.addRigidBody(&table);

  const double dt = 1.0 / rate;
  const ServeAnswer answer = stepServe(rate, to_crossing, [&] {
    world.stepSimulation(bt(dt), 1, bt(dt));
    return std::pair<V, V>(eigen(ball.getCenterOfMassPosition()), eigen(ball.getLinearVelocity()));
  });
  world.removeRigidBody(&table);
  world.removeRigidBody(&floor);
  world.removeRigidBody(&ball);
  return answer;
}

void BM_BulletServe(benchmark::State& state, double rate) {
  timePeer(state, rate, [rate](bool to_crossing) { return bulletServe(rate, to_crossing); });
}

#endif

#ifdef COLLISION_RESPONSE_WITH_ODE

struct OdeWorld {
  dWorldID world;
  dJointGroupID contacts;
};

/// As the accuracy harness (bench/accuracy/ode.cpp): contact joints with bounce = e,
/// bounce_vel = 0, mu = 0.
void odeNearCallback(void* data, dGeomID first, dGeomID second) {
  auto* w = static_cast<OdeWorld*>(data);
  dContact contact[4];
  const int found = dCollide(first, second, 4, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < found; ++i) {
    contact[i].surface.mode = dContactBounce;
    contact[i].surface.mu = 0;
    contact[i].surface.bounce = kRestitution;
    contact[i].surface.bounce_vel = 0;
    const dJointID joint = dJointCreateContact(w->world, w->contacts, &contact[i]);
    dJointAttach(joint, dGeomGetBody(first), dGeomGetBody(second));
  }
}

/// ODE (dWorldStep) as the accuracy harness sets it up. ODE's linear damping s scales the
/// velocity by 1 - s after each step (dxStepBody): s = 1 - exp(-c dt) makes that exp(-c dt),
/// the linear drag's decay over the step.
ServeAnswer odeServe(double rate, bool to_crossing) {
  const ServeReference& ref = reference();
  const double dt = 1.0 / rate;
  OdeWorld w{dWorldCreate(), dJointGroupCreate(0)};
  const dSpaceID space = dHashSpaceCreate(nullptr);
  dWorldSetGravity(w.world, 0, 0, -kG);
  const dBodyID ball = dBodyCreate(w.world);
  dMass mass;
  dMassSetSphereTotal(&mass, kMass, kRadius);
  dBodySetMass(ball, &mass);
  const V p0 = ref.vector("initial_position"), v0 = ref.vector("initial_velocity");
  const V w0 = ref.vector("angular_velocity");
  dBodySetPosition(ball, p0.x(), p0.y(), p0.z());
  dBodySetLinearVel(ball, v0.x(), v0.y(), v0.z());
  dBodySetAngularVel(ball, w0.x(), w0.y(), w0.z());
  dBodySetAutoDisableFlag(ball, 0);
  dBodySetLinearDamping(ball, 1 - std::exp(-dampingRate() * dt));
  dGeomSetBody(dCreateSphere(space, kRadius), ball);
  dCreatePlane(space, 0, 0, 1, 0);
  const dGeomID table = dCreateBox(space, kTableSize.x(), kTableSize.y(), kTableSize.z());
  dGeomSetPosition(table, kTableCentre.x(), kTableCentre.y(), kTableCentre.z());

  const ServeAnswer answer = stepServe(rate, to_crossing, [&] {
    dSpaceCollide(space, &w, &odeNearCallback);
    dWorldStep(w.world, dt);
    dJointGroupEmpty(w.contacts);
    const dReal* p = dBodyGetPosition(ball);
    const dReal* v = dBodyGetLinearVel(ball);
    return std::pair<V, V>(V(p[0], p[1], p[2]), V(v[0], v[1], v[2]));
  });
  dJointGroupDestroy(w.contacts);
  dSpaceDestroy(space);
  dWorldDestroy(w.world);
  return answer;
}

void BM_OdeServe(benchmark::State& state, double rate) {
  timePeer(state, rate, [rate](bool to_crossing) { return odeServe(rate, to_crossing); });
}

#endif

}  // namespace
}  // namespace collision_response::bench

int main(int argc, char** argv) {
  namespace bench = collision_response::bench;
  try {
    bench::reference();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  }
#ifdef COLLISION_RESPONSE_WITH_ODE
  dInitODE2(0);
#endif
  benchmark::RegisterBenchmark("BM_PredictGravityTenBounces", bench::BM_PredictGravityTenBounces)
      ->Unit(benchmark::kMicrosecond);
  const std::vector<std::string> tolerances = {"1e-6", "1e-8", "1e-9", "1e-10", "1e-12"};
  for (const std::string& tolerance : tolerances) {
    benchmark::RegisterBenchmark(("BM_PredictServe/" + tolerance).c_str(), bench::BM_PredictServe,
                                 std::stod(tolerance), true)
        ->Unit(benchmark::kMicrosecond);
  }
  // The same queries without the plane: what the crossing's search costs.
  for (const std::string& tolerance : tolerances) {
    benchmark::RegisterBenchmark(("BM_PredictServeBounces/" + tolerance).c_str(),
                                 bench::BM_PredictServe, std::stod(tolerance), false)
        ->Unit(benchmark::kMicrosecond);
  }
#ifdef COLLISION_RESPONSE_WITH_BULLET
  for (const int rate : {240, 1000, 10000}) {
    benchmark::RegisterBenchmark(("BM_BulletServe/" + std::to_string(rate)).c_str(),
                                 bench::BM_BulletServe, static_cast<double>(rate))
        ->Unit(benchmark::kMicrosecond);
  }
#endif
#ifdef COLLISION_RESPONSE_WITH_ODE
  for (const int rate : {240, 1000, 10000}) {
    benchmark::RegisterBenchmark(("BM_OdeServe/" + std::to_string(rate)).c_str(),
                                 bench::BM_OdeServe, static_cast<double>(rate))
        ->Unit(benchmark::kMicrosecond);
  }
#endif
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
#ifdef COLLISION_RESPONSE_WITH_ODE
  dCloseODE();
#endif
  return 0;
}

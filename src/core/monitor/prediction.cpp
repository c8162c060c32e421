#include "collision_response/core/prediction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "collision_response/core/validation.h"
#include "geometry/narrow_phase.h"

namespace collision_response::core {
namespace {

Status checkPositive(double value, const std::string& field, const char* unit) {
  if (!(std::isfinite(value) && value > 0)) {
    return Error{
        field, std::string("must be a finite number > 0 ") + unit + ", got " + formatNumber(value)};
  }
  return Ok{};
}

/// The request's own numbers: the state finite, the horizon and count positive, the sample
/// period and the plane usable, the body's numbers and effects as a scene's body would need them.
Status checkRequest(const Scene& scene, const PredictionRequest& request) {
  const BodySpec& body = request.body;
  if (auto status = checkName(body.id, "body.id"); !status) return status;
  if (auto status = checkMass(body.mass, "body.mass"); !status) return status;
  if (auto status = checkRadius(body.radius, "body.radius"); !status) return status;
  if (body.material.empty()) return Error{"body.material", "is required (a material name)"};
  if (auto status = scene.materials.checkMaterial(body.material, "body.material"); !status) {
    return status;
  }
  if (auto status = checkResolvablePosition(request.state.position, "body.position"); !status) {
    return status;
  }
  if (auto status = checkFinite(request.state.velocity, "body.velocity"); !status) return status;
  if (auto status = checkFinite(request.state.angular_velocity, "body.angular_velocity"); !status) {
    return status;
  }
  if (!std::isfinite(request.state.time)) {
    return Error{"header.stamp", "must be an instant on the node's time line"};
  }
  if (auto status = checkPositive(request.horizon, "horizon", "s"); !status) return status;
  if (request.max_impacts == 0) return Error{"max_impacts", "must be > 0"};
  if (!(std::isfinite(request.sample_period) && request.sample_period >= 0)) {
    return Error{"sample_period", "must be a finite number >= 0 s (0: no samples), got " +
                                      formatNumber(request.sample_period)};
  }
  if (request.crossing) {
    if (auto status = checkFinite(request.crossing->normal, "crossing_normal"); !status) {
      return status;
    }
    if (request.crossing->normal.isZero()) {
      return Error{"crossing_normal", "is zero: a plane needs a direction"};
    }
    if (!std::isfinite(request.crossing->offset)) {
      return Error{"crossing_offset",
                   "must be finite, got " + formatNumber(request.crossing->offset)};
    }
  }
  if (request.effects.magnus && !request.effects.spin) {
    return Error{"effects",
                 "names magnus without spin: the Magnus force comes from the spin, "
                 "which only the spin effect carries (add spin)"};
  }
  if (!request.effects.spin && !request.state.angular_velocity.isZero()) {
    return Error{"body.angular_velocity",
                 "is nonzero but the effects do not include spin: the model would ignore it "
                 "(add spin to effects, or send zero)"};
  }
  if (auto status = checkAirCoefficient(body.drag_coefficient, "drag_coefficient"); !status) {
    return status;
  }
  return checkAirCoefficient(body.lift_coefficient, "lift_coefficient");
}

/// The scene the prediction runs: the body alone among the scene's obstacles and, held where
/// `live` has them at `time`, the other bodies as immovable spheres.
Scene sceneAhead(const Scene& scene, const ImpactMonitor* live, const PredictionRequest& request) {
  Scene ahead = scene;
  ahead.detection = Detection::kContinuous;
  ahead.effects = request.effects;
  BodySpec body = request.body;
  body.position = request.state.position;
  body.velocity = request.state.velocity;
  body.angular_velocity = request.state.angular_velocity;
  ahead.bodies = {body};
  if (live == nullptr) return ahead;
  for (const BodySpec& other : scene.bodies) {
    if (other.id == body.id) continue;
    const auto index = live->bodyIndex(other.id);
    const auto state = index ? live->predictedState(*index, request.state.time) : std::nullopt;
    if (!state) continue;  // not tracked: nowhere known
    ObstacleSpec held;
    held.id = other.id;
    held.shape = ObstacleShape::kSphere;
    held.material = other.material;
    held.position = state->first;
    held.radius = other.radius;
    ahead.obstacles.push_back(held);
  }
  return ahead;
}

/// The obstacles on tf frames where `live` placed them; an error where the state starts inside
/// an obstacle.
Status placeObstacles(ImpactMonitor& model, const ImpactMonitor* live,
                      const PredictionRequest& request, double contact_tolerance) {
  std::map<std::string, std::size_t> live_index;
  for (std::size_t i = 0; live != nullptr && i < live->obstacleCount(); ++i) {
    live_index[live->obstacle(i).id] = i;
  }
  for (std::size_t i = 0; i < model.obstacleCount(); ++i) {
    const ObstacleSpec& obstacle = model.obstacle(i);
    if (!obstacle.frame.empty()) {
      const auto found = live_index.find(obstacle.id);
      if (found == live_index.end()) continue;
      if (auto placed = live->obstaclePose(found->second)) {
        placed->pose.time -= request.state.time;  // onto the prediction's line, from 0
        model.placeObstacle(i, *placed);
      }
    }
    const auto placed = model.obstaclePose(i);
    if (!placed) continue;  // on a frame tf has not given yet
    const ContactGeometry g =
        contactGeometry(request.state.position, request.body.radius, shapeAt(*placed, 0.0),
                        contact_tolerance, [] { return Eigen::Vector3d(Eigen::Vector3d::Zero()); });
    if (g.gap < -g.tolerance) {
      return Error{"body.position", "is " + formatNumber(-g.gap) + " m inside obstacle '" +
                                        obstacle.id + "' (a prediction starts in free space)"};
    }
  }
  return Ok{};
}

BodyStateSample stateOf(const ImpactMonitor& model, double time) {
  const auto state = model.predictedState(0, time);
  BodyStateSample sample;
  sample.time = time;
  sample.position = state->first;
  sample.velocity = state->second;
  sample.angular_velocity = model.predictedAngularVelocity(0, time);
  return sample;
}

double across(const Plane& plane, const Eigen::Vector3d& position) {
  return plane.normal.dot(position) - plane.offset;
}

/// The first crossing of `plane` within (from, to] by the model `before` (at `from`) advanced:
/// bisected on the instant, the model advanced afresh from `before` to each middle.
BodyStateSample bisectCrossing(const ImpactMonitor& before, const Plane& plane, double from,
                               double to) {
  const double side = across(plane, stateOf(before, from).position);
  double open = from, closed = to;
  for (int i = 0; i < 200; ++i) {
    const double middle = open + 0.5 * (closed - open);
    if (!(middle > open && middle < closed)) break;
    ImpactMonitor probe = before;
    probe.advance(middle, {});
    const double now = across(plane, stateOf(probe, middle).position);
    ((now > 0) == (side > 0) && now != 0 ? open : closed) = middle;
  }
  ImpactMonitor probe = before;
  probe.advance(closed, {});
  return stateOf(probe, closed);
}

}  // namespace

Expected<Prediction> predictImpacts(const Scene& scene, const ImpactMonitor* live,
                                    const MonitorSettings& settings,
                                    const PredictionRequest& request) {
  if (auto status = checkRequest(scene, request); !status) return status.error();
  Scene ahead = sceneAhead(scene, live, request);
  if (auto status = validateScene(ahead, "request"); !status) return status.error();
  MonitorSettings model_settings = settings;
  model_settings.body_timeout = std::numeric_limits<double>::infinity();
  model_settings.detect_impacts = true;
  auto model = std::make_shared<ImpactMonitor>(ahead, model_settings);
  if (auto status = placeObstacles(*model, live, request, settings.contact_tolerance); !status) {
    return status.error();
  }
  // The prediction's own time line starts at the state (0), where its instants hold every digit.
  const double start = 0.0;
  BodyStateSample state = request.state;
  state.body = 0;
  state.time = start;
  model->step(start, {state});

  Prediction prediction;
  std::vector<std::string> cut;
  double horizon = request.horizon;
  if (horizon > kPredictionMaxHorizon) {
    horizon = kPredictionMaxHorizon;
    cut.push_back("the horizon is cut to " + formatNumber(kPredictionMaxHorizon) + " s");
  }
  std::size_t max_impacts = request.max_impacts;
  if (max_impacts > kPredictionMaxImpacts) {
    max_impacts = kPredictionMaxImpacts;
    cut.push_back("impacts are cut to " + std::to_string(kPredictionMaxImpacts));
  }
  const double end = start + horizon;
  // Advanced piece by piece where samples or a crossing are asked for, else at once.
  double period = request.sample_period > 0 ? request.sample_period
                  : request.crossing        ? kCrossingSearchPeriod
                                            : horizon;
  std::size_t pieces = static_cast<std::size_t>(std::ceil(horizon / period));
  if (request.sample_period > 0 && pieces > kPredictionMaxSamples) {
    period = horizon / static_cast<double>(kPredictionMaxSamples);
    pieces = kPredictionMaxSamples;
    cut.push_back("samples are cut to " + std::to_string(kPredictionMaxSamples) + ", every " +
                  formatNumber(period) + " s");
  }
  if (request.sample_period > 0) prediction.samples.push_back(stateOf(*model, start));
  double now = start;
  bool truncated = false;
  for (std::size_t piece = 1; piece <= pieces && now < end; ++piece) {
    const double next =
        piece == pieces ? end : std::min(end, start + period * static_cast<double>(piece));
    const ImpactMonitor before = *model;
    StepReport report = model->advance(next, {});
    truncated = truncated || report.truncated;
    const std::size_t room = max_impacts - prediction.impacts.size();
    if (report.impacts.size() >= room) {
      // The last impact asked for: the prediction ends at its instant, with every impact there
      // (advanced 4 ulps past it, so that the root found again from the same start is inside).
      const double impact_time = report.impacts[room - 1].time;
      const double last = impact_time + 4 * std::numeric_limits<double>::epsilon() *
                                            std::max(std::abs(impact_time), 1e-300);
      *model = before;
      report = model->advance(last, {});
      prediction.impacts.insert(prediction.impacts.end(), report.impacts.begin(),
                                report.impacts.end());
      prediction.contacts = report.contacts;
      now = last;
      if (request.crossing && !prediction.crossing &&
          (across(*request.crossing, stateOf(before, before.now()).position) > 0) !=
              (across(*request.crossing, stateOf(*model, now).position) > 0)) {
        prediction.crossing = bisectCrossing(before, *request.crossing, before.now(), now);
      }
      break;
    }
    prediction.impacts.insert(prediction.impacts.end(), report.impacts.begin(),
                              report.impacts.end());
    prediction.contacts = report.contacts;
    if (request.crossing && !prediction.crossing &&
        (across(*request.crossing, stateOf(before, before.now()).position) > 0) !=
            (across(*request.crossing, stateOf(*model, next).position) > 0)) {
      prediction.crossing = bisectCrossing(before, *request.crossing, before.now(), next);
    }
    now = next;
    if (request.sample_period > 0) prediction.samples.push_back(stateOf(*model, now));
  }
  if (truncated) cut.push_back("the monitor's guard on impacts at one instant ran out");
  prediction.final_state = stateOf(*model, now);
  prediction.cut_short = !cut.empty();
  for (const std::string& reason : cut) {
    prediction.message += (prediction.message.empty() ? "" : "; ") + reason;
  }
  prediction.model = std::move(model);
  return prediction;
}

}  // namespace collision_response::core

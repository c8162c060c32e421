#include "collision_response/core/prediction.h"

#include <time.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/mass_properties.h"
#include "collision_response/core/triangle_mesh.h"
#include "collision_response/core/validation.h"
#include "geometry/narrow_phase.h"
#include "monitor/crossing.h"
#include "monitor/shaped_prediction.h"

namespace collision_response::core {

double threadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

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
    // Exactly zero only: any other length is a direction (Eigen's isZero() is approximate).
    if ((request.crossing->normal.array() == 0.0).all()) {
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
  if (isShapedBody(body)) return checkShapedRequest(request);
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

/// Another body of the scene held where it is, as an immovable obstacle of its shape at its
/// position and orientation `at`: a ball a sphere, a box, cylinder or capsule that shape, a
/// mesh body the convex hull of its vertices (as the monitor moves it); empty where the hull
/// cannot be made (the scene's checks refuse such a body first).
std::optional<ObstacleSpec> heldAsObstacle(const BodySpec& body, const Eigen::Vector3d& position,
                                           const Eigen::Quaterniond& orientation) {
  Shape shape = shapeOf(body);
  if (body.shape == BodyShape::kMesh) {
    if (!body.mesh) return std::nullopt;
    const auto hull = convexHull(body.mesh->vertices(), "mesh");
    if (!hull) return std::nullopt;
    auto triangles = TriangleMesh::build(hull->vertices, hull->triangles, "mesh");
    if (!triangles) return std::nullopt;
    shape = Mesh{std::move(triangles.value())};
  }
  ObstacleSpec held;
  held.id = body.id;
  held.material = body.material;
  held.resource = body.resource;
  setShape(held, shape);
  held.position = position;  // after setShape: a sphere's centre is the body's, not its origin
  held.orientation = orientation;
  return held;
}

/// The scene the prediction runs: the body alone among the scene's obstacles and, held where
/// `live` has them at `time`, the other bodies as immovable obstacles of their shapes.
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
    auto held =
        heldAsObstacle(other, state->first, live->predictedOrientation(*index, request.state.time));
    if (held) ahead.obstacles.push_back(std::move(*held));
  }
  return ahead;
}

/// Where `live` placed each tf-attached obstacle of `ahead` (by id), its time moved onto the
/// prediction's line (from 0 at the request's state).
std::vector<std::optional<PlacedShape>> livePlacements(const Scene& ahead,
                                                       const ImpactMonitor* live,
                                                       const PredictionRequest& request) {
  std::vector<std::optional<PlacedShape>> placed(ahead.obstacles.size());
  if (live == nullptr) return placed;
  std::map<std::string, std::size_t> live_index;
  for (std::size_t i = 0; i < live->obstacleCount(); ++i) live_index[live->obstacle(i).id] = i;
  for (std::size_t i = 0; i < ahead.obstacles.size(); ++i) {
    if (ahead.obstacles[i].frame.empty()) continue;
    const auto found = live_index.find(ahead.obstacles[i].id);
    if (found == live_index.end()) continue;
    placed[i] = live->obstaclePose(found->second);
    if (placed[i]) placed[i]->pose.time -= request.state.time;  // onto the prediction's line
  }
  return placed;
}

/// The obstacles on tf frames where the live monitor placed them.
void placeLiveObstacles(ImpactMonitor& model, const PredictionStart& start) {
  for (std::size_t i = 0; i < model.obstacleCount(); ++i) {
    if (!model.obstacle(i).frame.empty() && i < start.placed.size() && start.placed[i]) {
      model.placeObstacle(i, *start.placed[i]);
    }
  }
}

/// The obstacles placed (placeLiveObstacles); an error where the ball starts inside one.
Status placeObstacles(ImpactMonitor& model, const PredictionStart& start) {
  placeLiveObstacles(model, start);
  const PredictionRequest& request = start.request;
  for (std::size_t i = 0; i < model.obstacleCount(); ++i) {
    const auto placed = model.obstaclePose(i);
    if (!placed) continue;  // on a frame tf has not given yet
    const ContactGeometry g = contactGeometry(
        request.state.position, request.body.radius, shapeAt(*placed, 0.0),
        start.settings.contact_tolerance, [] { return Eigen::Vector3d(Eigen::Vector3d::Zero()); });
    if (g.gap < -g.tolerance) {
      return Error{"body.position", "is " + formatNumber(-g.gap) + " m inside obstacle '" +
                                        model.obstacle(i).id +
                                        "' (a prediction starts in free space)"};
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

/// One prediction run: the model advanced piece by piece (at the sample period, the crossing's
/// search period, or the whole horizon at once), each piece's impacts, samples and crossing
/// gathered. A piece is never advanced twice on the same model: where its work must be looked at
/// again (the last impact asked for falls in it, or the crossing does after the body's motion
/// changed in it), a fresh model is advanced through the same pieces to its start, which gives
/// the same motion to the bit.
class PredictionRun {
 public:
  PredictionRun(const PredictionStart& start, const PredictionBudget& budget, double began)
      : start_(start),
        ahead_(start.ahead),
        settings_(start.settings),
        request_(start.request),
        budget_(budget),
        began_(began) {}

  /// A model at the state's instant, 0.
  std::shared_ptr<ImpactMonitor> fresh() const {
    auto model = std::make_shared<ImpactMonitor>(ahead_, settings_);
    placeObstacles(*model, start_);  // checked before
    BodyStateSample state = request_.state;
    state.body = 0;
    state.time = 0.0;
    model->step(0.0, {state});
    return model;
  }

  Prediction run(std::vector<std::string>& cut) {
    budget(cut);
    Prediction prediction;
    bool spent = false;
    auto model = fresh();
    if (request_.sample_period > 0) prediction.samples.push_back(stateOf(*model, 0.0));
    double now = 0.0;
    bool truncated = false;
    double stalled_at = INFINITY;  // the earliest stall of the body's flight through air
    for (std::size_t piece = 1; piece <= pieces_ && now < horizon_; ++piece) {
      if (piece > 1 && outOfBudget()) {
        spent = true;
        break;
      }
      const double next = pieceEnd(piece);
      const Eigen::Vector3d from = stateOf(*model, now).position;
      StepReport report = model->advance(next, {});
      truncated = truncated || report.truncated;
      noteStalls(report, stalled_at);
      const std::size_t room = max_impacts_ - prediction.impacts.size();
      std::shared_ptr<const ImpactMonitor> before;
      if (report.impacts.size() >= room) {
        // The last impact asked for: the prediction ends at its instant, with every impact
        // there. Advanced afresh from the piece's start to a hair past it (1e-12 of the piece, 16
        // ulps): found again over a shorter span, an instant on an integrated path (a flight
        // through air) moves by its bisection's resolution, 1e-13 of the span.
        const double impact_time = report.impacts[room - 1].time;
        const double last =
            std::min(next, impact_time + 1e-12 * (next - now) +
                               16 * std::numeric_limits<double>::epsilon() * std::abs(impact_time));
        before = replayTo(piece);
        model = std::make_shared<ImpactMonitor>(*before);
        report = model->advance(last, {});
        truncated = truncated || report.truncated;
        noteStalls(report, stalled_at);
        next_ = last;
      } else {
        next_ = next;
      }
      prediction.impacts.insert(prediction.impacts.end(), report.impacts.begin(),
                                report.impacts.end());
      prediction.contacts = report.contacts;
      findCrossing(*model, before, piece, now, from, prediction);
      now = next_;
      if (before) break;
      if (request_.sample_period > 0) prediction.samples.push_back(stateOf(*model, now));
    }
    if (truncated) cut.push_back("the monitor's guard on impacts at one instant ran out");
    if (stalled_at < INFINITY) {
      cut.push_back(stalledFlightCut(stalled_at));
    }
    if (spent) {
      prediction.out_of_budget = true;
      cut.push_back(budget_.name + " (" + formatNumber(budget_.seconds) +
                    " s of CPU) ran out at +" + formatNumber(now) +
                    " s: the impacts, samples and state up to there");
    }
    prediction.final_state = stateOf(*model, now);
    prediction.model = std::move(model);
    return prediction;
  }

 private:
  static void noteStalls(const StepReport& report, double& stalled_at) {
    for (const StalledFlight& flight : report.stalled) {
      stalled_at = std::min(stalled_at, flight.stalled);
    }
  }

  bool outOfBudget() const {
    if (!(budget_.seconds > 0)) return false;
    const double spent = (budget_.clock ? budget_.clock() : threadCpuSeconds()) - began_;
    return spent >= budget_.seconds;
  }

  /// The horizon, impacts and pieces within the budgets (kPredictionMax*); what was cut is said.
  void budget(std::vector<std::string>& cut) {
    horizon_ = request_.horizon;
    if (horizon_ > kPredictionMaxHorizon) {
      horizon_ = kPredictionMaxHorizon;
      cut.push_back("the horizon is cut to " + formatNumber(kPredictionMaxHorizon) + " s");
    }
    max_impacts_ = request_.max_impacts;
    if (max_impacts_ > kPredictionMaxImpacts) {
      max_impacts_ = kPredictionMaxImpacts;
      cut.push_back("impacts are cut to " + std::to_string(kPredictionMaxImpacts));
    }
    period_ = request_.sample_period > 0 ? request_.sample_period
              : request_.crossing        ? kCrossingSearchPeriod
              : budget_.seconds > 0      ? std::min(horizon_, kBudgetCheckPeriod)
                                         : horizon_;
    // Compared as a double before it is a count: a sample period of 5e-324 s makes it infinite.
    // Without samples: at most kPredictionMaxHorizon / kCrossingSearchPeriod = 3,000 pieces.
    const double pieces = std::ceil(horizon_ / period_);
    if (request_.sample_period > 0 && !(pieces <= static_cast<double>(kPredictionMaxSamples))) {
      period_ = horizon_ / static_cast<double>(kPredictionMaxSamples);
      pieces_ = kPredictionMaxSamples;
      cut.push_back("samples are cut to " + std::to_string(kPredictionMaxSamples) + ", every " +
                    formatNumber(period_) + " s");
    } else {
      pieces_ = static_cast<std::size_t>(pieces);
    }
  }

  double pieceEnd(std::size_t piece) const {
    return piece == pieces_ ? horizon_ : std::min(horizon_, period_ * static_cast<double>(piece));
  }

  /// A fresh model advanced through the pieces before `piece`: where the run's model was then.
  std::shared_ptr<ImpactMonitor> replayTo(std::size_t piece) const {
    auto model = fresh();
    for (std::size_t k = 1; k < piece; ++k) model->advance(pieceEnd(k), {});
    return model;
  }

  /// The plane's first crossing within the piece just advanced (from `now` to next_), if its
  /// centre changed sides: on the body's one motion where it had one all along the piece, else
  /// by models advanced afresh from the piece's start (`before`, or replayed).
  void findCrossing(const ImpactMonitor& model, std::shared_ptr<const ImpactMonitor> before,
                    std::size_t piece, double now, const Eigen::Vector3d& from,
                    Prediction& prediction) const {
    if (!request_.crossing || prediction.crossing) return;
    const Plane& plane = *request_.crossing;
    if ((across(plane, from) > 0) == (across(plane, stateOf(model, next_).position) > 0)) return;
    if (!before && model.motionSince(0) <= now) {
      // One motion all along the piece: the model at its end has it.
      prediction.crossing =
          bisectCrossing(plane, now, next_, [&](double t) { return stateOf(model, t); });
      return;
    }
    if (!before) before = replayTo(piece);
    prediction.crossing = bisectCrossing(plane, now, next_, [&](double t) {
      if (t == now) return stateOf(*before, t);
      ImpactMonitor probe = *before;  // the model at the piece's start, advanced afresh to t
      probe.advance(t, {});
      return stateOf(probe, t);
    });
  }

  const PredictionStart& start_;
  const Scene& ahead_;
  const MonitorSettings& settings_;
  const PredictionRequest& request_;
  const PredictionBudget& budget_;
  double began_ = 0.0;  ///< budget_'s clock when the prediction began
  double horizon_ = 0.0, period_ = 0.0, next_ = 0.0;
  std::size_t max_impacts_ = 0, pieces_ = 0;
};

}  // namespace

Expected<PredictionStart> startPrediction(const Scene& scene, const ImpactMonitor* live,
                                          const MonitorSettings& settings,
                                          const PredictionRequest& request) {
  if (auto status = checkRequest(scene, request); !status) return status.error();
  PredictionStart start;
  start.ahead = sceneAhead(scene, live, request);
  start.request = request;
  start.settings = settings;
  start.settings.body_timeout = std::numeric_limits<double>::infinity();
  start.settings.detect_impacts = true;
  start.placed = livePlacements(start.ahead, live, request);
  return start;
}

Expected<Prediction> runPrediction(const PredictionStart& start, const PredictionBudget& budget) {
  const double began =
      budget.seconds > 0 ? (budget.clock ? budget.clock() : threadCpuSeconds()) : 0.0;
  const bool shaped = isShapedBody(start.request.body);
  if (auto status = validateScene(start.ahead, "request",
                                  shaped ? MovingShapes::kAny : MovingShapes::kSpheresOnly);
      !status) {
    return status.error();
  }
  // The prediction's own time line starts at the state (0), where its instants hold every digit.
  std::vector<std::string> cut;
  Prediction prediction;
  if (shaped) {
    // The model holds the scene ahead (the obstacles placed, the answer's ids); it moves
    // nothing: the shaped body's run does.
    auto model = std::make_shared<ImpactMonitor>(start.ahead, start.settings);
    placeLiveObstacles(*model, start);
    auto shaped_prediction = runShapedPrediction(start, budget, began, std::move(model), cut);
    if (!shaped_prediction) return shaped_prediction.error();
    prediction = std::move(shaped_prediction.value());
  } else {
    {
      ImpactMonitor check(start.ahead, start.settings);
      if (auto status = placeObstacles(check, start); !status) return status.error();
    }
    prediction = PredictionRun(start, budget, began).run(cut);
  }
  prediction.cut_short = !cut.empty();
  for (const std::string& reason : cut) {
    prediction.message += (prediction.message.empty() ? "" : "; ") + reason;
  }
  return prediction;
}

Expected<Prediction> predictImpacts(const Scene& scene, const ImpactMonitor* live,
                                    const MonitorSettings& settings,
                                    const PredictionRequest& request,
                                    const PredictionBudget& budget) {
  auto start = startPrediction(scene, live, settings, request);
  if (!start) return start.error();
  return runPrediction(*start, budget);
}

}  // namespace collision_response::core

// Where will the ball go? One body's motion predicted ahead of time by the monitor's own model:
// its impacts with the scene's obstacles and with the other bodies, held where they are, up to a
// horizon; the state it ends in (resting and rolling by the lasting-contact model); and, when
// asked, its path sampled and the instant its centre first crosses a plane. No ROS.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/expected.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"
#include "collision_response/core/shape.h"

namespace collision_response::core {

/// What one prediction may do (README, "Prediction"). A request past them is answered with what
/// was found within them, and says so.
inline constexpr double kPredictionMaxHorizon = 60.0;  ///< s
inline constexpr std::size_t kPredictionMaxImpacts = 1000;
inline constexpr std::size_t kPredictionMaxSamples = 10000;
/// Without samples, the first crossing of a plane is looked for at this period, then bisected to
/// the last bit of its instant: a crossing and a return within one period are not seen.
inline constexpr double kCrossingSearchPeriod = 0.02;  ///< s
/// With a budget (PredictionBudget), a request without samples or a plane is advanced in pieces
/// at most this long, so that the budget is looked at this often along the horizon.
inline constexpr double kBudgetCheckPeriod = 0.1;  ///< s

struct PredictionRequest {
  BodySpec body;                ///< the body predicted (id, mass, radius, material, coefficients)
  BodyStateSample state;        ///< its state, in the scene's fixed frame (`body` is ignored)
  double horizon = 0.0;         ///< s, > 0
  std::size_t max_impacts = 0;  ///< > 0
  Effects effects;              ///< the effects that run (the caller chooses: scene or request)
  double sample_period = 0.0;   ///< s: > 0, the path at this period; 0: none
  /// The plane whose first crossing by the body's centre is reported (either way across).
  std::optional<Plane> crossing;
};

/// Every instant of a prediction (impacts, states, contacts) is in s after the request's state:
/// the prediction runs on a time line of its own, from 0.
struct Prediction {
  /// The impacts, in time order (each as the monitor reports them; `model` names their ids).
  std::vector<ImpactRecord> impacts;
  /// The state at the end: at the horizon, or at the instant of the last impact asked for (a hair
  /// after it: 1e-12 of the piece it fell in, 16 ulps).
  BodyStateSample final_state;
  /// The lasting contacts at the end (resting, sliding, rolling).
  std::vector<ContactRecord> contacts;
  std::vector<BodyStateSample> samples;     ///< from the state's instant, every sample_period
  std::optional<BodyStateSample> crossing;  ///< the first crossing of the request's plane
  /// A budget cut the prediction short (kPredictionMax*, the monitor's guards, the CPU budget);
  /// `message` says which.
  bool cut_short = false;
  /// The CPU budget (PredictionBudget) ran out: the prediction ends where it got to.
  bool out_of_budget = false;
  std::string message;
  /// The model the prediction ran on: the body (index 0), the obstacles and the held bodies.
  std::shared_ptr<const ImpactMonitor> model;
};

/// A CPU budget for one prediction: looked at between the pieces the horizon is advanced in (the
/// sample period, the crossing's search period, or kBudgetCheckPeriod); once spent, the
/// prediction stops where it got to and answers what it found up to there (its impacts, samples
/// and the state there), cut short, the message naming the budget.
/// The calling thread's CPU time, s (CLOCK_THREAD_CPUTIME_ID): a prediction's default budget
/// clock, and the scene player's measure of what a period costs.
double threadCpuSeconds();

struct PredictionBudget {
  double seconds = 0.0;                              ///< s of `clock`; 0: no budget
  std::string name = "the prediction's CPU budget";  ///< as the message names it
  /// s: the clock the budget is spent on, called on the thread that runs the prediction; empty:
  /// that thread's CPU time (threadCpuSeconds), so that other threads' work does not count.
  std::function<double()> clock;
};

/// What a prediction reads of the live monitor, copied at once by startPrediction (the scene, the
/// other bodies where the monitor has them at the request's instant, the obstacles where it
/// placed them: O(bodies + obstacles), no motion computed), so that runPrediction needs the
/// monitor no more and may run on another thread while it steps on.
struct PredictionStart {
  Scene ahead;  ///< the body alone among the obstacles and the other bodies, held
  PredictionRequest request;
  MonitorSettings settings;
  /// Per obstacle of `ahead`: where the live monitor placed it (a tf-attached one), its time on
  /// the prediction's line; empty: where `ahead` puts it.
  std::vector<std::optional<PlacedShape>> placed;
};

/// The part of predictImpacts that reads `live`; the request's own numbers are checked here.
Expected<PredictionStart> startPrediction(const Scene& scene, const ImpactMonitor* live,
                                          const MonitorSettings& settings,
                                          const PredictionRequest& request);
/// The rest of predictImpacts, on `start` alone, within `budget`.
Expected<Prediction> runPrediction(const PredictionStart& start,
                                   const PredictionBudget& budget = {});

/// Predicts `request.body` from `request.state` in `scene` (validated), under `request.effects`,
/// with continuous detection. Obstacles on tf frames are where `live` last placed them, moving
/// on as they move now; the other bodies `live` tracks are held where `live` predicts them at
/// the state's instant (immovable spheres); without `live`, the scene's fixed obstacles only.
/// Errors name the request's field: a state that is not finite or is inside an obstacle, a
/// horizon or count not > 0, a body's number out of range, an effect the body cannot have.
/// Within `budget` (none by default): see PredictionBudget.
Expected<Prediction> predictImpacts(const Scene& scene, const ImpactMonitor* live,
                                    const MonitorSettings& settings,
                                    const PredictionRequest& request,
                                    const PredictionBudget& budget = {});

}  // namespace collision_response::core

// Where will the ball go? One body's motion predicted ahead of time by the monitor's own model:
// its impacts with the scene's obstacles and with the other bodies, held where they are, up to a
// horizon; the state it ends in (resting and rolling by the lasting-contact model); and, when
// asked, its path sampled and the instant its centre first crosses a plane. No ROS.
#pragma once

#include <Eigen/Core>
#include <cstddef>
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
  /// A budget cut the prediction short (kPredictionMax*, or the monitor's guards); `message` says
  /// which.
  bool cut_short = false;
  std::string message;
  /// The model the prediction ran on: the body (index 0), the obstacles and the held bodies.
  std::shared_ptr<const ImpactMonitor> model;
};

/// Predicts `request.body` from `request.state` in `scene` (validated), under `request.effects`,
/// with continuous detection. Obstacles on tf frames are where `live` last placed them, moving
/// on as they move now; the other bodies `live` tracks are held where `live` predicts them at
/// the state's instant (immovable spheres); without `live`, the scene's fixed obstacles only.
/// Errors name the request's field: a state that is not finite or is inside an obstacle, a
/// horizon or count not > 0, a body's number out of range, an effect the body cannot have.
Expected<Prediction> predictImpacts(const Scene& scene, const ImpactMonitor* live,
                                    const MonitorSettings& settings,
                                    const PredictionRequest& request);

}  // namespace collision_response::core

#include "monitor/shaped_prediction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/rigid_impact.h"
#include "collision_response/core/validation.h"
#include "contact/shaped_lasting.h"
#include "monitor/crossing.h"
#include "monitor/shaped_motion.h"

namespace collision_response::core {

std::string stalledFlightCut(double stalled) {
  return "the flight through air stalled at +" + formatNumber(stalled) +
         " s (its integrator could take no further step: a speed or an air factor too large for "
         "it); the body is held where it got to from there, its state at the horizon too";
}

Status checkShapedRequest(const PredictionRequest& request) {
  if (!std::isfinite(request.body.mass)) {
    return Error{"body.mass", "must be finite: an immovable body is not predicted"};
  }
  if (auto status =
          checkBodyShape(request.body, [](const char* key) { return std::string("body.") + key; });
      !status) {
    return status;
  }
  if (auto principal = principalBody(request.body, "body"); !principal) return principal.error();
  return checkOrientation(request.state.orientation, "body.orientation");
}

namespace {

/// The shaped body's prediction: the engine's flights between impacts (ShapedMotion), each
/// flight's samples and crossing, within the budgets.
class ShapedRun {
 public:
  ShapedRun(const PredictionStart& start, const PredictionBudget& budget, double began,
            const ImpactMonitor& model, PrincipalBody principal)
      : request_(start.request),
        scene_(start.ahead),
        budget_(budget),
        began_(began),
        model_(model),
        principal_(std::move(principal)) {}

  Expected<Prediction> run(std::vector<std::string>& cut) {
    limits(cut);
    std::vector<ShapedObstacle> obstacles;
    for (std::size_t o = 0; o < model_.obstacleCount(); ++o) {
      if (auto placed = model_.obstaclePose(o)) obstacles.push_back({o, *placed});
    }
    ShapedScene scene;
    scene.acceleration = scene_.effects.gravity ? scene_.gravity : Eigen::Vector3d::Zero();
    scene.restitution_threshold = scene_.restitution_threshold;
    scene.restitution = [this](std::size_t o) { return restitutionWith(o); };
    scene.friction = [this](std::size_t o) { return frictionWith(o); };
    scene.integration_tolerance = scene_.contact_integration_tolerance;
    scene.air = bodyAirFactors(request_.body, scene_.air_density, scene_.effects.drag,
                               scene_.effects.magnus);
    scene.flight_tolerance = scene_.flight_integration_tolerance;
    BodyStateSample state = request_.state;
    state.body = 0;
    state.time = 0.0;
    auto created = ShapedMotion::create(principal_, std::move(obstacles), std::move(scene), state);
    if (!created) return created.error();
    ShapedMotion& motion = created.value();
    for (bool first = true;; first = false) {
      const TumblingBody body = motion.flight();
      const double time = motion.time();
      if (first) {
        if (const auto inside = motion.insideAtStart()) {
          return Error{"body.position", "is inside obstacle '" + model_.obstacle(*inside).id +
                                            "' (a prediction starts in free space)"};
        }
        if (request_.sample_period > 0) prediction_.samples.push_back(motion.stateOn(body, 0.0));
      }
      if (outOfBudget()) {
        cut.push_back(budget_.name + " (" + formatNumber(budget_.seconds) +
                      " s of CPU) ran out at +" + formatNumber(time) +
                      " s: the impacts, samples and state up to there");
        prediction_.out_of_budget = true;
        return finish(motion, body, time);
      }
      const auto found = motion.next(horizon_, prediction_.impacts);
      if (!found) return found.error();
      flightUntil(motion, body, time, found->time);
      if (const double stalled = motion.stalledAt(); stalled <= found->time) {
        cut.push_back(stalledFlightCut(stalled));
        return finish(motion, body, horizon_);
      }
      switch (found->event) {
        case ShapedMotion::Event::kFree:
          return finish(motion, body, horizon_);
        case ShapedMotion::Event::kGrazed:
          continue;
        case ShapedMotion::Event::kLasting: {
          auto ended = lastingFrom(motion, body, found->time, cut);
          if (ended) return std::move(*ended);
          continue;  // it resumes its events
        }
        case ShapedMotion::Event::kImpact:
          break;
      }
      rests_from_ = motion.flatBouncesEnd();
      if (prediction_.impacts.size() >= max_impacts_) {
        return finish(motion, motion.flight(), motion.time());
      }
      if (!motion.leave(horizon_)) {
        const TumblingBody after = motion.flight();
        auto ended = lastingFrom(motion, after, motion.time(), cut);
        if (ended) return std::move(*ended);
      }
    }
  }

 private:
  /// The horizon, impacts and samples within the budgets (as a sphere's prediction).
  void limits(std::vector<std::string>& cut) {
    horizon_ = std::min(request_.horizon, kPredictionMaxHorizon);
    if (request_.horizon > kPredictionMaxHorizon) {
      cut.push_back("the horizon is cut to " + formatNumber(kPredictionMaxHorizon) + " s");
    }
    max_impacts_ = std::min(request_.max_impacts, kPredictionMaxImpacts);
    if (request_.max_impacts > kPredictionMaxImpacts) {
      cut.push_back("impacts are cut to " + std::to_string(kPredictionMaxImpacts));
    }
    period_ = request_.sample_period;
    if (period_ > 0 &&
        !(std::ceil(horizon_ / period_) <= static_cast<double>(kPredictionMaxSamples))) {
      period_ = horizon_ / static_cast<double>(kPredictionMaxSamples);
      cut.push_back("samples are cut to " + std::to_string(kPredictionMaxSamples) + ", every " +
                    formatNumber(period_) + " s");
    }
  }

  bool outOfBudget() const {
    if (!(budget_.seconds > 0)) return false;
    return (budget_.clock ? budget_.clock() : threadCpuSeconds()) - began_ >= budget_.seconds;
  }

  /// The samples and the crossing of the flight from `from` to `to`.
  void flightUntil(const ShapedMotion& motion, const TumblingBody& body, double from, double to) {
    sampleUntil(from, to, [&](double t) { return motion.stateOn(body, t); });
  }

  Expected<double> restitutionWith(std::size_t obstacle) const {
    return scene_.materials.restitution(request_.body.material, model_.obstacle(obstacle).material,
                                        "body.material", "obstacle material");
  }

  Expected<double> frictionWith(std::size_t obstacle) const {
    if (!scene_.effects.friction) return 0.0;
    return scene_.materials.friction(request_.body.material, model_.obstacle(obstacle).material,
                                     "body.material", "obstacle material");
  }

  /// Why the prediction ends at a lasting contact with `obstacles` at `time`: `why`, what is not
  /// modelled of it (lastingFaces' or lastingOnFaces' refusal).
  std::string lastingContact(const std::vector<std::size_t>& obstacles, double time,
                             const std::string& why) const {
    std::string ids;
    for (const std::size_t o : obstacles) {
      ids += (ids.empty() ? "'" : ", '") + model_.obstacle(o).id + "'";
    }
    return "the body comes into lasting contact with " + ids + " at +" + formatNumber(time) +
           " s, which is not yet modelled (" + why + "), and the prediction ends there";
  }

  /// The body's state at `time` on a lasting motion.
  BodyStateSample stateOn(const LastingMotion& lasting, double time) const {
    BodyStateSample state;
    state.time = time;
    state.position = lasting.centreAt(time);
    state.velocity = lasting.velocityAt(time);
    state.angular_velocity = lasting.angularVelocityAt(time);
    state.orientation = lasting.orientationAt(time) * principal_.body_from_principal.conjugate();
    return state;
  }

  /// The contact the engine found to last at `time` (on `body`'s flight): where it is on one flat
  /// face, the body moves by lastingOnFace's motion (sampled; asked again where it `stops`) to
  /// the horizon or to where that motion ends; where it is not modelled, the prediction ends
  /// there, saying why. Empty where the motion ends with "resumes" (a body that tips until
  /// another corner reaches the face, or leaves it): its events go on from there.
  std::optional<Expected<Prediction>> lastingFrom(ShapedMotion& motion, const TumblingBody& body,
                                                  double time, std::vector<std::string>& cut) {
    const std::vector<std::size_t> with = motion.lastingWith();
    auto faces = motion.lastingFaces();
    if (!faces) {
      cut.push_back(lastingContact(with, time, faces.error().message()));
      return finish(motion, body, time);
    }
    LastingBody on = faces->first;
    for (bool first = true;; first = false) {
      auto lasting = lastingOnFaces(on, faces->second, motion.integrationTolerance());
      if (!lasting && first && lasting.error().field == "body.velocity" && motion.part(horizon_)) {
        return std::nullopt;  // no lasting contact: its points part from the face
      }
      if (!lasting) {
        cut.push_back(lastingContact(with, on.time, lasting.error().message()));
        BodyStateSample state;
        state.time = on.time;
        state.position = on.centre;
        state.velocity = on.velocity;
        state.angular_velocity = on.angular_velocity;
        state.orientation = on.orientation * principal_.body_from_principal.conjugate();
        return finishWith(motion, state);
      }
      const LastingMotion& along = *lasting;
      // Its lasting motion watches its faces alone: another obstacle it meets ends it first (a
      // strike's impact, or a touch that does not close found to last with both).
      const auto strike =
          motion.struckWhileLasting(along, with, on.time, std::min(along.until, horizon_));
      const double until = strike ? strike->time : std::min(along.until, horizon_);
      sampleUntil(on.time, until, [&](double t) { return stateOn(along, t); });
      if (strike || (until < horizon_ && along.ends == "resumes")) {
        const BodyStateSample there = stateOn(along, until);
        if (const auto refused = resumes_.refuse(until)) {  // beyond its bounds: cut there
          cut.push_back(lastingContact(with, until, *refused));
          return finishWith(motion, there);
        }
        if (Status status = motion.restartFrom(there); !status) {
          return Expected<Prediction>(status.error());
        }
        if (motion.insideAtStart()) {  // never through it
          cut.push_back(lastingContact(with, until, "its tipping ends inside the obstacle"));
          return finishWith(motion, there);
        }
        rests_from_.reset();
        return std::nullopt;  // its events go on from there: a strike's impact first
      }
      if (until >= horizon_ || along.ends != "stops") {
        if (until < horizon_) {
          cut.push_back("the body's lasting contact with '" + model_.obstacle(with.front()).id +
                        "' ends at +" + formatNumber(until) + " s (" + along.ends +
                        "), which is not yet modelled, and the prediction ends there");
        }
        for (const SupportForce& force : along.forcesAt(until)) {
          ContactRecord record;
          record.time = until;
          record.other = force.face < with.size() ? with[force.face] : with.front();
          record.other_is_obstacle = true;
          record.contact_point = force.point;
          record.normal = force.normal.isZero(0.0)
                              ? Eigen::Vector3d(-faces->second.at(force.face).normal)
                              : Eigen::Vector3d(-force.normal);
          record.normal_force = force.normal_force;
          record.friction_force = -force.friction_force;
          record.state = along.stateAt(until);
          // After a flat landing whose bounces accumulate, the contact lasts from their end (as
          // a ball's: doc/model.md, "Coming to rest").
          record.since = rests_from_ ? *rests_from_ : time;
          prediction_.contacts.push_back(record);
        }
        return finishWith(motion, stateOn(along, until));
      }
      on.time = until;
      on.centre = along.centreAt(until);
      on.velocity = along.velocityAt(until);
      on.angular_velocity = along.angularVelocityAt(until);
      on.orientation = along.orientationAt(until);
      if (!(along.until > along.start)) {
        cut.push_back(lastingContact(with, until, "its lasting motion ends where it starts"));
        return finishWith(motion, stateOn(along, until));
      }
    }
  }

  /// The samples and the crossing of a motion given by `state_at` from `from` to `to`.
  template <class StateAt>
  void sampleUntil(double from, double to, const StateAt& state_at) {
    if (period_ > 0) {
      for (double k = std::floor(from / period_) + 1;; ++k) {
        const double t = std::min(horizon_, k * period_);
        if (t > to || t <= from) break;
        if (prediction_.samples.empty() || prediction_.samples.back().time < t) {
          prediction_.samples.push_back(state_at(t));
        }
        if (t >= horizon_) break;
      }
    }
    if (!request_.crossing || prediction_.crossing) return;
    const Plane& plane = *request_.crossing;
    if ((across(plane, state_at(from).position) > 0) ==
        (across(plane, state_at(to).position) > 0)) {
      return;
    }
    prediction_.crossing = bisectCrossing(plane, from, to, state_at);
  }

  Expected<Prediction> finish(const ShapedMotion& motion, const TumblingBody& body, double time) {
    return finishWith(motion, motion.stateOn(body, time));
  }

  Expected<Prediction> finishWith(const ShapedMotion& motion, const BodyStateSample& state) {
    prediction_.final_state = state;
    if (const auto frictionless_at = motion.frictionlessAt()) {
      notes_.push_back(
          "friction at several points struck at once where the joint law does not apply "
          "(their e differ, or a point left apart would approach; first at +" +
          formatNumber(*frictionless_at) +
          " s) is not yet modelled: those impacts were frictionless");
    }
    return std::move(prediction_);
  }

 public:
  std::vector<std::string> notes_;

 private:
  const PredictionRequest& request_;
  const Scene& scene_;
  const PredictionBudget& budget_;
  double began_ = 0.0;
  const ImpactMonitor& model_;
  PrincipalBody principal_;
  Prediction prediction_;
  double horizon_ = 0.0, period_ = 0.0;
  std::size_t max_impacts_ = 0;
  std::optional<double> rests_from_;  // the last impact's flat bounces accumulate then
  ResumeGuard resumes_;               // a tipping's hand-overs to its events
};

}  // namespace

Expected<Prediction> runShapedPrediction(const PredictionStart& start,
                                         const PredictionBudget& budget, double began,
                                         std::shared_ptr<ImpactMonitor> model,
                                         std::vector<std::string>& cut) {
  auto principal = principalBody(start.request.body, "body");
  if (!principal) return principal.error();
  ShapedRun run(start, budget, began, *model, std::move(principal.value()));
  auto prediction = run.run(cut);
  if (!prediction) return prediction;
  // What the model simplified on the way (friction left out of impacts at several points) is
  // said in the message; it does not cut the prediction short.
  for (const std::string& note : run.notes_) {
    prediction.value().message += (prediction.value().message.empty() ? "" : "; ") + note;
  }
  prediction.value().model = std::move(model);
  return prediction;
}

}  // namespace collision_response::core

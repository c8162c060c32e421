#include "monitor/shaped_prediction.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/rigid_impact.h"
#include "collision_response/core/validation.h"
#include "geometry/narrow_phase.h"
#include "geometry/tumbling_contact.h"
#include "monitor/crossing.h"

namespace collision_response::core {

namespace {

/// The shape's points about the centre of mass in the principal frame: a box's corners, where
/// the frame is turned or the centre moved.
ConvexHull boxCorners(const Cuboid& box, const Eigen::Matrix3d& principal_from_body,
                      const Eigen::Vector3d& centre_of_mass) {
  ConvexHull hull;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0,
                               (corner & 4) ? 1.0 : -1.0);
    hull.vertices.push_back(principal_from_body *
                            (sign.cwiseProduct(box.half_size) - centre_of_mass));
  }
  return hull;
}

}  // namespace

Expected<PrincipalBody> principalBody(const BodySpec& body, const std::string& field) {
  if (body.shape == BodyShape::kMesh) {
    return Error{field + ".shape",
                 "not yet: a mesh body is not predicted (a box, cylinder, capsule or sphere is)"};
  }
  auto properties = bodyMassProperties(body, field + ".inertia");
  if (!properties) return properties.error();
  PrincipalBody principal;
  principal.mass = properties->mass;
  principal.centre_of_mass = properties->centre_of_mass;
  const Eigen::Matrix3d& inertia = properties->inertia;
  const bool diagonal = inertia(0, 1) == 0.0 && inertia(0, 2) == 0.0 && inertia(1, 2) == 0.0 &&
                        inertia(1, 0) == 0.0 && inertia(2, 0) == 0.0 && inertia(2, 1) == 0.0;
  Eigen::Matrix3d body_from_principal = Eigen::Matrix3d::Identity();
  if (diagonal) {
    principal.moments = inertia.diagonal();
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inertia);
    principal.moments = solver.eigenvalues();
    body_from_principal = solver.eigenvectors();
    if (body_from_principal.determinant() < 0) body_from_principal.col(2) *= -1.0;
  }
  principal.body_from_principal = Eigen::Quaterniond(body_from_principal);
  const bool moved = !diagonal || !principal.centre_of_mass.isZero(0.0);
  const Eigen::Matrix3d principal_from_body = body_from_principal.transpose();
  const Shape shape = shapeOf(body);
  if (const auto* sphere = std::get_if<Sphere>(&shape)) {
    principal.shape =
        Sphere{principal_from_body * (sphere->centre - principal.centre_of_mass), sphere->radius};
  } else if (const auto* box = std::get_if<Cuboid>(&shape)) {
    if (moved) {
      principal.shape = boxCorners(*box, principal_from_body, principal.centre_of_mass);
    } else {
      principal.shape = *box;
    }
  } else if (moved) {
    return Error{field + ".inertia",
                 "not yet: a cylinder's or a capsule's tensor must have no products of inertia "
                 "(its axis and two across it principal), as its uniform solid's has"};
  } else if (const auto* cylinder = std::get_if<Cylinder>(&shape)) {
    principal.shape = *cylinder;
  } else if (const auto* capsule = std::get_if<Capsule>(&shape)) {
    principal.shape = *capsule;
  }
  return principal;
}

Status checkShapedRequest(const PredictionRequest& request) {
  if (request.effects.air()) {
    return Error{"effects",
                 "names drag or magnus: not yet modelled for a shaped body (a box, cylinder or "
                 "capsule flies by gravity alone); leave them out"};
  }
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

/// A contact of the body with one obstacle at an instant.
struct ObstacleContact {
  std::size_t obstacle = 0;  ///< the model's index
  std::size_t slot = 0;      ///< in the run's placed obstacles
  TumblingContact contact;
};

/// The shaped body's run: flights between impacts, each flight's samples and crossing.
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
    for (std::size_t o = 0; o < model_.obstacleCount(); ++o) {
      if (auto placed = model_.obstaclePose(o)) obstacles_.push_back({o, *placed});
    }
    const Eigen::Vector3d acceleration =
        scene_.effects.gravity ? scene_.gravity : Eigen::Vector3d::Zero();
    double time = 0.0;
    Eigen::Vector3d centre = request_.state.position;
    Eigen::Vector3d velocity = request_.state.velocity;
    Eigen::Vector3d angular_velocity = request_.state.angular_velocity;
    Eigen::Quaterniond orientation =
        request_.state.orientation.normalized() * principal_.body_from_principal;
    for (bool first = true;; first = false) {
      auto created = TumblingBody::create(principal_.shape, principal_.moments, time, centre,
                                          velocity, acceleration, orientation, angular_velocity);
      if (!created) return created.error();
      const TumblingBody& body = *created;
      if (first) {
        if (auto status = checkStartsOutside(body); !status) return status.error();
        if (request_.sample_period > 0) prediction_.samples.push_back(stateAt(body, 0.0));
      }
      if (outOfBudget()) {
        cut.push_back(budget_.name + " (" + formatNumber(budget_.seconds) +
                      " s of CPU) ran out at +" + formatNumber(time) +
                      " s: the impacts, samples and state up to there");
        prediction_.out_of_budget = true;
        return finish(body, time);
      }
      const std::vector<ObstacleContact> contacts = firstContacts(body);
      const double until = contacts.empty() ? horizon_ : contacts.front().contact.time;
      flightUntil(body, time, until);
      if (contacts.empty()) return finish(body, horizon_);
      // An impact: every obstacle touching at the instant, each point of its manifold.
      const double at = until;
      SolverBody moving = solverBody(body, at);
      const auto resolved = resolve(body, moving, contacts, at);
      if (!resolved) return resolved.error();
      if (!*resolved) {
        // Touching without approaching: parting, or a contact that lasts. Found again where
        // the body was last known apart from it (a slow graze, a roll on a rim), it lasts.
        bool again = false;
        for (const ObstacleContact& c : contacts) {
          const Watched& w = obstacles_[c.slot];
          again = again || (w.parted && at == w.clear_from);
        }
        const auto apart = again ? std::nullopt : separation(body, at, contacts);
        if (!apart) {
          cut.push_back(lastingContact(contacts, at));
          return finish(body, at);
        }
        clearUntil(at, contacts, *apart);
        continue;
      }
      time = at;
      centre = body.positionAt(at);
      velocity = moving.velocity;
      angular_velocity = moving.angular_velocity;
      orientation = body.orientationAt(at);
      if (prediction_.impacts.size() >= max_impacts_) {
        auto after = TumblingBody::create(principal_.shape, principal_.moments, time, centre,
                                          velocity, acceleration, orientation, angular_velocity);
        if (!after) return after.error();
        return finish(*after, time);
      }
      // The points just struck leave their obstacles: the next contact with those is looked for
      // once they are apart (separation), with every other obstacle from now.
      auto after = TumblingBody::create(principal_.shape, principal_.moments, time, centre,
                                        velocity, acceleration, orientation, angular_velocity);
      if (!after) return after.error();
      const auto apart = separation(*after, time, contacts);
      if (!apart) {
        cut.push_back(lastingContact(contacts, at));
        return finish(*after, time);
      }
      clearUntil(at, contacts, *apart);
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

  Status checkStartsOutside(const TumblingBody& body) const {
    for (const Watched& w : obstacles_) {
      const SurfaceGap gap = gapAt(body, w.placed, 0.0);
      if (gap.overlapping || gap.gap_upper < 0) {
        return Error{"body.position", "is inside obstacle '" + model_.obstacle(w.obstacle).id +
                                          "' (a prediction starts in free space)"};
      }
    }
    return Ok{};
  }

  /// The body's state at `time` on its flight: the centre's, and the body frame's orientation.
  BodyStateSample stateAt(const TumblingBody& body, double time) const {
    BodyStateSample state;
    state.time = time;
    state.position = body.positionAt(time);
    state.velocity = body.velocityAt(time);
    state.angular_velocity = body.angularVelocityAt(time);
    state.orientation = body.orientationAt(time) * principal_.body_from_principal.conjugate();
    return state;
  }

  /// The earliest contacts (every obstacle touching then, within the instant's rounding), each
  /// obstacle searched from the instant it is known apart until (Watched::clear_from); none
  /// within the horizon: empty.
  std::vector<ObstacleContact> firstContacts(const TumblingBody& body) const {
    std::vector<ObstacleContact> found;
    for (std::size_t slot = 0; slot < obstacles_.size(); ++slot) {
      const PlacedShape& placed = obstacles_[slot].placed;
      const double start = obstacles_[slot].clear_from;
      if (!(start < horizon_)) continue;
      // The advancement's step budget may run out on a slow graze before the horizon: it goes
      // on from where it is known apart.
      for (double clear = start;;) {
        const FirstContactResult result = firstContact(body, placed, clear, horizon_ - clear);
        if (result.contact) {
          found.push_back({obstacles_[slot].obstacle, slot, *result.contact});
          break;
        }
        if (!(result.clear_until > clear && result.clear_until < horizon_)) break;
        clear = result.clear_until;
      }
    }
    if (found.empty()) return found;
    double earliest = std::numeric_limits<double>::infinity();
    for (const ObstacleContact& c : found) earliest = std::min(earliest, c.contact.time);
    const double together = earliest + kSimultaneous * std::max(1.0, std::abs(earliest));
    std::vector<ObstacleContact> first;
    for (ObstacleContact& c : found) {
      if (c.contact.time <= together) first.push_back(std::move(c));
    }
    return first;
  }

  /// The samples and the crossing of the flight from `from` to `to`.
  void flightUntil(const TumblingBody& body, double from, double to) {
    if (period_ > 0) {
      for (double k = std::floor(from / period_) + 1;; ++k) {
        const double t = std::min(horizon_, k * period_);
        if (t > to || t <= from) break;
        if (prediction_.samples.empty() || prediction_.samples.back().time < t) {
          prediction_.samples.push_back(stateAt(body, t));
        }
        if (t >= horizon_) break;
      }
    }
    if (!request_.crossing || prediction_.crossing) return;
    const Plane& plane = *request_.crossing;
    if ((across(plane, body.positionAt(from)) > 0) == (across(plane, body.positionAt(to)) > 0)) {
      return;
    }
    prediction_.crossing =
        bisectCrossing(plane, from, to, [&](double t) { return stateAt(body, t); });
  }

  /// The body as the impact's solver sees it at `time`.
  SolverBody solverBody(const TumblingBody& body, double time) const {
    SolverBody solver;
    solver.inverse_mass = 1.0 / principal_.mass;
    solver.velocity = body.velocityAt(time);
    solver.angular_velocity = body.angularVelocityAt(time);
    solver.inertia_kind = InverseInertiaKind::kTensor;
    const Eigen::Matrix3d rotation = body.orientationAt(time).toRotationMatrix();
    solver.inverse_inertia =
        rotation * principal_.moments.cwiseInverse().asDiagonal() * rotation.transpose();
    return solver;
  }

  /// An obstacle as the solver sees it at `time`: immovable, moving on as it moves.
  static SolverBody obstacleBody(const PlacedShape& placed, double time) {
    const PlacedShape now = shapeAt(placed, time);
    SolverBody solver;
    solver.velocity = now.pose.velocity;
    solver.angular_velocity = now.pose.angular_velocity;
    solver.inertia_kind = InverseInertiaKind::kTensor;
    return solver;
  }

  /// After an impact or a graze at `time` with `contacts`' obstacles, apart from them at
  /// `apart`: those are looked at again from `apart`, every other one from `time` (no contact
  /// with it before: the contacts were the earliest), never from an earlier instant than it
  /// was known apart until. Each obstacle keeps its own instant: one struck before a graze of
  /// another is not looked at again from that impact's instant, where its points still touch
  /// it and would be found again at once, for ever.
  void clearUntil(double time, const std::vector<ObstacleContact>& contacts, double apart) {
    for (Watched& w : obstacles_) {
      w.clear_from = std::max(w.clear_from, time);
      w.parted = false;
    }
    for (const ObstacleContact& c : contacts) {
      obstacles_[c.slot].clear_from = apart;
      obstacles_[c.slot].parted = true;
    }
  }

  /// Resolves the impact at `time` of `moving` (updated) with the contacts' points: one point
  /// by Chatterjee and Ruina's law with the pair's friction, several at once by the joint
  /// frictionless rule (rigid_impact.h). False where no point approaches (a lasting contact).
  Expected<bool> resolve(const TumblingBody& body, SolverBody& moving,
                         const std::vector<ObstacleContact>& contacts, double time) {
    std::vector<SolverBody> bodies{moving};
    std::vector<ClusterContact> points;
    std::vector<std::size_t> point_obstacle;
    double fastest = 0.0;
    for (const ObstacleContact& c : contacts) {
      const PlacedShape& placed = obstacles_[c.slot].placed;
      bodies.push_back(obstacleBody(placed, time));
      const auto restitution = restitutionWith(c.obstacle);
      if (!restitution) return restitution.error();
      for (const ManifoldPoint& point : c.contact.manifold) {
        ClusterContact contact;
        contact.a = 0;
        contact.b = bodies.size() - 1;
        contact.normal = c.contact.closest.normal;
        contact.point = 0.5 * (point.point_a + point.point_b);
        contact.lever_a = point.lever_a;
        contact.lever_b = point.lever_b;
        contact.restitution = *restitution;
        const Eigen::Vector3d relative = body.pointVelocityAt(time, point.point_a) -
                                         bodies.back().velocity -
                                         bodies.back().angular_velocity.cross(point.lever_b);
        fastest = std::max(fastest, contact.normal.dot(relative));
        points.push_back(contact);
        point_obstacle.push_back(c.obstacle);
      }
    }
    if (!(fastest > 0)) return false;
    // Bounces that accumulate (a body settling, rocking from edge to edge) would go on for ever
    // in finitely many seconds: where even an elastic rebound could lift no point by more than
    // kSettled of the body's reach, the contact is taken to last.
    const double lift = body.acceleration().norm() * kSettled * body.reach();
    if (fastest * fastest <= 2 * lift) return false;
    const bool bounces = fastest >= scene_.restitution_threshold;
    if (!bounces) {
      for (ClusterContact& point : points) point.restitution = 0.0;
    }
    const Eigen::Vector3d velocity_before = moving.velocity;
    const Eigen::Vector3d angular_before = moving.angular_velocity;
    std::vector<ImpactRecord> records;
    if (points.size() == 1) {
      const auto friction = frictionWith(point_obstacle.front());
      if (!friction) return friction.error();
      auto outcome = resolveRigidImpact(bodies[0], bodies[1], points.front(),
                                        points.front().restitution, *friction);
      if (!outcome) return outcome.error();
      ImpactRecord record = recordOf(points.front(), point_obstacle.front(), time, bodies[1]);
      record.impulse = outcome->normal_impulse;
      record.friction_impulse = outcome->tangential_impulse.norm();
      record.energy_lost = outcome->energy_lost;
      records.push_back(record);
    } else {
      bool frictional = false;
      for (const std::size_t o : point_obstacle) {
        const auto friction = frictionWith(o);
        if (!friction) return friction.error();
        frictional = frictional || *friction > 0;
      }
      if (frictional && !frictionless_said_) {
        frictionless_said_ = true;
        frictionless_at_ = time;
      }
      auto outcomes = resolveRigidSimultaneous(bodies, points);
      if (!outcomes) return outcomes.error();
      for (std::size_t k = 0; k < points.size(); ++k) {
        ImpactRecord record = recordOf(points[k], point_obstacle[k], time, bodies[points[k].b]);
        record.impulse = (*outcomes)[k].impulse;
        record.energy_lost = (*outcomes)[k].energy_lost;
        records.push_back(record);
      }
    }
    moving = bodies[0];
    for (ImpactRecord& record : records) {
      record.velocity_a_before = velocity_before;
      record.angular_velocity_a_before = angular_before;
      record.velocity_a_after = moving.velocity;
      record.angular_velocity_a_after = moving.angular_velocity;
      prediction_.impacts.push_back(record);
    }
    return true;
  }

  ImpactRecord recordOf(const ClusterContact& point, std::size_t obstacle, double time,
                        const SolverBody& other) const {
    ImpactRecord record;
    record.time = time;
    record.body_a = 0;
    record.other = obstacle;
    record.other_is_obstacle = true;
    record.contact_point = point.point;
    record.normal = point.normal;
    record.restitution = point.restitution;
    record.velocity_b_before = other.velocity;
    record.velocity_b_after = other.velocity;
    record.angular_velocity_b_before = other.angular_velocity;
    record.angular_velocity_b_after = other.angular_velocity;
    return record;
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

  /// After an impact at `time`: the instant from which the obstacles it left are looked at again,
  /// once every point of the body is apart from them: a step short enough that no point of the
  /// body moves by half the manifold's band relative to them (V s + A s^2 / 2 <= band / 2, V the
  /// bound on the points' relative speed, A on their acceleration: a point further than the band
  /// from an obstacle at the impact was not struck, and cannot reach it within the step), after
  /// which the gap to each obstacle must be open. Where it is not (the points struck leave too
  /// slowly to part: plastic, or bounces that accumulate), or where nothing moves at all, the
  /// contact lasts: empty.
  std::optional<double> separation(const TumblingBody& body, double time,
                                   const std::vector<ObstacleContact>& left) const {
    double speed = body.velocityAt(time).norm() + body.angularSpeedBound() * body.reach();
    double acceleration = body.acceleration().norm();
    for (const ObstacleContact& c : left) {
      const PlacedShape now = shapeAt(obstacles_[c.slot].placed, time);
      const double turning = now.pose.angular_velocity.norm();
      const double arm =
          (body.positionAt(time) - now.pose.transform.translation()).norm() + body.reach();
      speed += now.pose.velocity.norm() + turning * arm;
      acceleration += turning * (now.pose.velocity.norm() + turning * arm);
    }
    if (!(speed > 0) && !(acceleration > 0)) return std::nullopt;  // at rest, touching
    const double band = FirstContactOptions{}.manifold_band;
    const double step = std::max(band / (speed + std::sqrt(speed * speed + acceleration * band)),
                                 4 * std::numeric_limits<double>::epsilon() * std::abs(time));
    const double apart = time + step;
    if (!(apart < horizon_)) return apart;
    for (const ObstacleContact& c : left) {
      const SurfaceGap gap = gapAt(body, obstacles_[c.slot].placed, apart);
      if (gap.overlapping || !(gap.gap > 0)) return std::nullopt;
    }
    return apart;
  }

  std::string lastingContact(const std::vector<ObstacleContact>& contacts, double time) const {
    std::string ids;
    for (const ObstacleContact& c : contacts) {
      ids += (ids.empty() ? "'" : ", '") + model_.obstacle(c.obstacle).id + "'";
    }
    return "the body comes into lasting contact with " + ids + " at +" + formatNumber(time) +
           " s: a shaped body's lasting contact (resting, sliding, rolling, tipping) is not yet "
           "modelled, and the prediction ends there";
  }

  Expected<Prediction> finish(const TumblingBody& body, double time) {
    prediction_.final_state = stateAt(body, time);
    if (frictionless_said_) {
      extra_.push_back(
          "friction at several points struck at once (a face or an edge landing, "
          "first at +" +
          formatNumber(frictionless_at_) +
          " s) is not yet modelled: those impacts were frictionless");
    }
    return std::move(prediction_);
  }

 public:
  std::vector<std::string> extra_;

 private:
  /// A rebound lifting no point by more than this fraction of the body's reach: settled.
  static constexpr double kSettled = 1e-6;
  /// Contacts this close to the earliest (relative to the instant, 1e-12) strike together.
  static constexpr double kSimultaneous = 1e-12;

  const PredictionRequest& request_;
  const Scene& scene_;
  const PredictionBudget& budget_;
  double began_ = 0.0;
  const ImpactMonitor& model_;
  PrincipalBody principal_;
  /// An obstacle placed, and from when it is looked at: no contact with it before clear_from;
  /// parted: clear_from is where the body was found apart from it after touching it.
  struct Watched {
    std::size_t obstacle = 0;
    PlacedShape placed;
    double clear_from = 0.0;
    bool parted = false;
  };
  std::vector<Watched> obstacles_;
  Prediction prediction_;
  double horizon_ = 0.0, period_ = 0.0;
  std::size_t max_impacts_ = 0;
  bool frictionless_said_ = false;
  double frictionless_at_ = 0.0;
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
  cut.insert(cut.end(), run.extra_.begin(), run.extra_.end());
  prediction.value().model = std::move(model);
  return prediction;
}

}  // namespace collision_response::core

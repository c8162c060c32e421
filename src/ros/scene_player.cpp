#include "collision_response/ros/scene_player.h"

#include <geometry_msgs/TransformStamped.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "collision_response/BodyStateArray.h"
#include "collision_response/core/body_shape.h"
#include "collision_response/core/prediction.h"
#include "collision_response/core/restitution.h"
#include "collision_response/core/validation.h"
#include "collision_response/ros/conversions.h"
#include "collision_response/ros/scene_loader.h"

namespace collision_response {
namespace {

using P = ScenePlayerParams;

/// Periods a late timer callback still publishes (the node's bound on an update, doc/model.md
/// "Lasting contact": about ten periods); further behind, the player skips to the newest.
constexpr std::int64_t kMaxCatchUp = 10;
/// The replay window holds one model of the scene per period: at most this many.
constexpr double kMaxReplayPeriods = 1000.0;

const KeyTable<MovingFrame>& frameKeys() {
  static const KeyTable<MovingFrame> kKeys = {
      textKey<MovingFrame>(
          "frame", [](MovingFrame& f) -> std::string& { return f.frame; }, core::checkFrameId,
          true),
      textKey<MovingFrame>(
          "parent", [](MovingFrame& f) -> std::string& { return f.parent; }, core::checkFrameId),
      {"position", false,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, MovingFrame& frame) {
         const auto vector = readVector3(value, field);
         if (!vector) return core::Status(vector.error());
         if (auto status = core::checkFinite(*vector, field); !status) return status;
         frame.position = *vector;
         return core::Status(core::Ok{});
       }},
      {"velocity", false,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, MovingFrame& frame) {
         const auto vector = readVector3(value, field);
         if (!vector) return core::Status(vector.error());
         if (auto status = core::checkFinite(*vector, field); !status) return status;
         frame.velocity = *vector;
         return core::Status(core::Ok{});
       }},
  };
  return kKeys;
}

struct PlayerPart {
  std::vector<MovingFrame> frames;
};

const KeyTable<PlayerPart>& playerKeys() {
  static const KeyTable<PlayerPart> kKeys = {
      {"frames", false,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, PlayerPart& part) {
         if (auto status = checkArray(value, field); !status) return status;
         for (int i = 0; i < value.size(); ++i) {
           MovingFrame frame;
           if (auto status = readKeys(value[i], frameKeys(),
                                      indexKey(field, static_cast<std::size_t>(i)), frame);
               !status) {
             return status;
           }
           part.frames.push_back(frame);
         }
         return core::Status(core::Ok{});
       }},
  };
  return kKeys;
}

}  // namespace

const KeyTable<ScenePlayerParams>& ScenePlayerParams::keys() {
  static const KeyTable<P> kKeys = {
      {"scene", true,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, P&) {
         return checkStruct(value, field);  // loadScene reads it
       }},
      {"player", false,
       [](const XmlRpc::XmlRpcValue& value, const std::string& field, P& params) {
         PlayerPart part;
         if (auto status = readKeys(value, playerKeys(), field, part); !status) return status;
         params.frames = part.frames;
         return core::Status(core::Ok{});
       }},
      numberKey<P>(
          "rate", [](P& p) -> double& { return p.rate; }, checkRate),
      numberKey<P>(
          "duration", [](P& p) -> double& { return p.duration; }, checkDurationOrZero),
      numberKey<P>(
          "start_delay", [](P& p) -> double& { return p.start_delay; }, checkDurationOrZero),
      numberKey<P>(
          "contact_tolerance", [](P& p) -> double& { return p.contact_tolerance; },
          core::checkContactTolerance),
      boolKey<P>("report_restitution", [](P& p) -> bool& { return p.report_restitution; }),
      numberKey<P>(
          "replay_window", [](P& p) -> double& { return p.replay_window; }, checkDurationOrZero),
  };
  return kKeys;
}

core::Expected<ScenePlayerParams> ScenePlayerParams::load(const XmlRpc::XmlRpcValue& tree,
                                                          const std::string& ns) {
  ScenePlayerParams params;
  if (tree.getType() != XmlRpc::XmlRpcValue::TypeStruct || !tree.hasMember("scene")) {
    return core::Error{joinKey(ns, "scene"), "is required (load a scene file)"};
  }
  if (auto status = readKeys(tree, keys(), ns, params); !status) return status.error();
  if (params.replay_window * params.rate > kMaxReplayPeriods) {
    // One model of the scene is kept per period of the window: the default shrinks to 1,000
    // periods at a rate above 4 kHz (README, "Parameters"); a value given is refused.
    if (!tree.hasMember("replay_window")) {
      params.replay_window = kMaxReplayPeriods / params.rate;
      return params;
    }
    return core::Error{joinKey(ns, "replay_window"),
                       core::formatNumber(params.replay_window) + " s at ~rate " +
                           core::formatNumber(params.rate) + " Hz is " +
                           core::formatNumber(params.replay_window * params.rate) +
                           " periods: at most " + core::formatNumber(kMaxReplayPeriods)};
  }
  return params;
}

ScenePlayer::ScenePlayer(const ros::NodeHandle& node, const ros::NodeHandle& private_node)
    : node_(node), private_node_(private_node) {}

bool ScenePlayer::initialize() {
  const std::string ns = private_node_.getNamespace();
  XmlRpc::XmlRpcValue tree;
  if (!ros::param::get(ns, tree)) tree = XmlRpc::XmlRpcValue();
  auto params = ScenePlayerParams::load(tree, ns);
  if (!params) {
    ROS_FATAL_STREAM("scene_player: bad parameter: " << params.error().message());
    return false;
  }
  // The robot's links too: the impacts the node publishes name them.
  auto scene =
      loadScene(tree["scene"], joinKey(ns, "scene"), parameterServerUrdf(joinKey(ns, "scene")));
  if (!scene) {
    ROS_FATAL_STREAM("scene_player: bad scene: " << scene.error().message());
    return false;
  }
  scene_ = std::move(scene.value());
  params_ = std::move(params.value());
  for (MovingFrame& frame : params_.frames) {
    if (frame.parent.empty()) frame.parent = scene_.fixed_frame;
  }
  indexing_ = std::make_unique<core::ImpactMonitor>(scene_, core::MonitorSettings{});

  ROS_INFO_STREAM("scene_player: " << scene_.bodies.size() << " bodies at " << params_.rate
                                   << " Hz, duration " << params_.duration
                                   << " s (0: until stopped), " << params_.frames.size()
                                   << " moving frames");

  state_publisher_ = node_.advertise<BodyStateArray>("body_states", 100);
  apex_publisher_ = node_.advertise<BodyState>("apexes", 100);
  impact_subscriber_ = node_.subscribe("impacts", 100, &ScenePlayer::onImpacts, this);
  created_ = ros::Time::now();
  timer_ = node_.createTimer(ros::Duration(1.0 / params_.rate), &ScenePlayer::onTimer, this);
  return true;
}

void ScenePlayer::onTimer(const ros::TimerEvent& event) {
  if (stopping_) return;
  const ros::Time now = event.current_real;
  if (!playback_) {
    // Start once the monitor listens and the start delay is over (so a printer can connect).
    if ((now - created_).toSec() < params_.start_delay ||
        state_publisher_.getNumSubscribers() == 0) {
      return;
    }
    start_ = now;
    playback_ = std::make_unique<core::Playback>(scene_, params_.contact_tolerance, 0.0,
                                                 params_.replay_window);
  }
  playPeriodsDue(now);
}

void ScenePlayer::playPeriodsDue(const ros::Time& now) {
  const double rate = params_.rate;
  // Period k is the instant k / rate s after the start; the last one is at or before `duration`.
  const double last = params_.duration > 0 ? std::floor(params_.duration * rate + 1e-9)
                                           : std::numeric_limits<double>::infinity();
  const double due = std::min(std::floor(sinceStart(now) * rate + 1e-9), last);
  if (due >= static_cast<double>(next_period_)) {
    const auto newest = static_cast<std::int64_t>(due);
    if (newest - next_period_ >= kMaxCatchUp) {
      // Too far behind to publish every period without falling further behind: the newest
      // alone, the others counted and said.
      const std::int64_t skipped = newest - next_period_;
      const double from = static_cast<double>(next_period_) / rate;
      skipped_ += skipped;
      next_period_ = newest;
      ROS_WARN_STREAM_THROTTLE(
          5.0, "scene_player: fell behind: the "
                   << skipped << " periods from " << from << " s to "
                   << static_cast<double>(newest - 1) / rate
                   << " s of the scene were not published (more than " << kMaxCatchUp
                   << " periods late), the newest, at " << static_cast<double>(newest) / rate
                   << " s, is; so far " << playedSummary() << ". Playing one period took "
                   << 1000.0 * last_period_cpu_ << " ms of CPU against a period of "
                   << 1000.0 / rate
                   << " ms: the machine is busy, or the scene costs more than ~rate allows");
    }
    const double began = core::threadCpuSeconds();
    const std::int64_t first = next_period_;
    for (; next_period_ <= newest; ++next_period_) {
      const ros::Time stamp =
          start_ + ros::Duration(static_cast<double>(next_period_) / params_.rate);
      publishStates(stamp);
      publishApexes(stamp);
      ++published_;
    }
    last_period_cpu_ =
        (core::threadCpuSeconds() - began) / static_cast<double>(next_period_ - first);
  }
  if (static_cast<double>(next_period_) > last) {
    stopping_ = true;
    ROS_INFO_STREAM("scene_player: " << params_.duration << " s played: " << playedSummary()
                                     << "; stopping");
    // A moment for the line to reach rosout before the node goes.
    stop_timer_ = node_.createWallTimer(
        ros::WallDuration(0.5), [](const ros::WallTimerEvent&) { ros::shutdown(); }, true);
  }
}

std::string ScenePlayer::playedSummary() const {
  std::ostringstream line;
  line << next_period_ << " periods of " << 1.0 / params_.rate << " s, " << published_
       << " states published, " << skipped_
       << " periods skipped; impacts not applied: " << late_impacts_ << " heard too late, "
       << stale_impacts_ << " found from states sent before an earlier impact was heard";
  return line.str();
}

void ScenePlayer::publishStates(const ros::Time& time) {
  for (const MovingFrame& frame : params_.frames) {
    geometry_msgs::TransformStamped transform;
    transform.header.stamp = time;
    transform.header.frame_id = frame.parent;
    transform.child_frame_id = frame.frame;
    const Eigen::Vector3d position = frame.position + frame.velocity * sinceStart(time);
    transform.transform.translation = toVector3Msg(position);
    transform.transform.rotation.w = 1.0;
    broadcaster_.sendTransform(transform);
  }
  BodyStateArray array;
  array.header.stamp = time;
  array.header.frame_id = scene_.fixed_frame;
  const double t = sinceStart(time);
  for (std::size_t i = 0; i < scene_.bodies.size(); ++i) {
    BodyState state;
    state.header = array.header;
    state.id = scene_.bodies[i].id;
    state.pose.position = toPointMsg(playback_->position(i, t));
    state.pose.orientation = toQuaternionMsg(playback_->orientation(i, t));
    state.twist.linear = toVector3Msg(playback_->velocity(i, t));
    state.twist.angular = toVector3Msg(playback_->angularVelocity(i, t));
    array.states.push_back(state);
  }
  state_publisher_.publish(array);
}

void ScenePlayer::onImpacts(const ImpactArray::ConstPtr& message) {
  if (!playback_) return;
  // In continuous detection the contact point is exact (the surfaces touch there), so each body
  // restarts one radius back along the normal from it; in discrete detection the bodies overlap
  // at the sample, and each restarts where the player had it (Playback::applyImpacts).
  const bool exact_contact = scene_.detection == core::Detection::kContinuous;
  // The state that revealed these impacts (the message's stamp), from the start.
  const double revealed = sinceStart(message->header.stamp);
  const auto bodyIds = [&](const core::ImpactRecord& record) {
    std::vector<std::string> ids{indexing_->body(record.body_a).id};
    if (!record.other_is_obstacle) ids.push_back(indexing_->body(record.other).id);
    return ids;
  };
  std::vector<core::ImpactRecord> records;
  std::vector<const Impact*> heard;
  for (const Impact& impact : message->impacts) {
    auto record = toImpactRecord(impact, *indexing_, sinceStart(impact.header.stamp));
    if (!record) continue;
    // Found from states the player sent before it heard of an earlier impact of one of these
    // bodies that it could not play itself (below): the node's motion there was not the scene's.
    bool stale = false;
    for (const std::string& id : bodyIds(*record)) {
      const auto found = unheard_.find(id);
      if (found == unheard_.end()) continue;
      // (The stamps are the periods': half a period apart from a period is past it.)
      if (revealed > found->second.second + 0.5 / params_.rate) {
        unheard_.erase(found);  // states sent since carry that impact
      } else if (record->time > found->second.first) {
        stale = true;
      }
    }
    if (stale) {
      ++stale_impacts_;
      ROS_WARN_STREAM_THROTTLE(
          5.0, "scene_player: the impact of '"
                   << impact.body_a << "' and '" << impact.body_b << "' at "
                   << sinceStart(impact.header.stamp)
                   << " s was found from states sent before the player heard of an earlier impact "
                      "of theirs (on a tf-attached obstacle, which the player cannot resolve "
                      "itself): not applied ("
                   << stale_impacts_ << " so far)");
      continue;
    }
    records.push_back(std::move(*record));
    heard.push_back(&impact);
  }
  const std::vector<std::size_t> refused =
      playback_->applyImpacts(*indexing_, records, exact_contact);
  // An impact on a tf-attached obstacle under continuous detection: the player did not resolve
  // it in what it played (it does not place those obstacles), so the states it sent from its
  // instant up to the newest lack it, and the node's impacts along those states' motion (up to
  // the next state's, found along the tracks of the one before) are not the scene's.
  const double newest = static_cast<double>(next_period_ - 1) / params_.rate;
  for (std::size_t k = 0; k < records.size(); ++k) {
    const core::ImpactRecord& record = records[k];
    if (!exact_contact || !record.other_is_obstacle ||
        indexing_->obstacle(record.other).frame.empty() ||
        std::find(refused.begin(), refused.end(), k) != refused.end() || !(newest > record.time)) {
      continue;
    }
    for (const std::string& id : bodyIds(record)) {
      unheard_[id] = {record.time, newest + 1.0 / params_.rate};
    }
  }
  late_impacts_ += static_cast<std::int64_t>(refused.size());
  for (const std::size_t k : refused) {
    // Heard more than ~replay_window after its instant was played: the bodies go on without it
    // (under continuous detection by the player's own resolution of it where the player knows
    // the other side; otherwise into it). Never silent.
    ROS_WARN_STREAM_THROTTLE(
        5.0, "scene_player: the impact of '"
                 << heard[k]->body_a << "' and '" << heard[k]->body_b << "' at "
                 << sinceStart(heard[k]->header.stamp) << " s came more than ~replay_window ("
                 << params_.replay_window
                 << " s) after that instant was played: not applied, so those bodies go on "
                    "without the node's answer (by the player's own, or into what they met)");
  }
}

void ScenePlayer::publishApexes(const ros::Time& time) {
  for (const core::Apex& apex : playback_->apexesUntil(sinceStart(time))) {
    const core::BodySpec& body = scene_.bodies[apex.body];
    BodyState state;
    state.header.stamp = start_ + ros::Duration(apex.time);
    state.header.frame_id = scene_.fixed_frame;
    state.id = body.id;
    state.pose.position = toPointMsg(apex.position);
    state.pose.orientation.w = 1.0;  // an apex is of the centre's flight (core::Apex)
    state.twist.linear = toVector3Msg(apex.velocity);
    state.twist.angular = toVector3Msg(apex.angular_velocity);
    apex_publisher_.publish(state);
    // The seed's method is a ball's (its lowest point one radius below its centre, whatever it
    // turned): a shaped body's lowest point moves as it turns, and is not reported.
    if (!params_.report_restitution || apex.impacts_before != 1 || core::isShapedBody(body)) {
      continue;
    }
    // The seed's method: dropped from rest, e from the heights of the lowest point above the
    // first plane obstacle (the floor), the drop's from the scene's initial position.
    const auto floor = std::find_if(
        scene_.obstacles.begin(), scene_.obstacles.end(), [](const core::ObstacleSpec& o) {
          return o.shape == core::ObstacleShape::kPlane && o.frame.empty();
        });
    if (floor == scene_.obstacles.end()) continue;
    const double drop = floor->normal.dot(body.position) - floor->offset - body.radius;
    const double bounce = floor->normal.dot(apex.position) - floor->offset - body.radius;
    const auto measured = scene_.materials.restitution(body.material, floor->material);
    const auto recovered = core::restitutionFromHeights(drop, bounce);
    if (!recovered) {
      ROS_WARN_STREAM("scene_player: no e for '" << body.id
                                                 << "': " << recovered.error().message());
      continue;
    }
    std::printf("restitution %-26s table %.3f  recovered %.15f  relative error %.1e\n",
                body.material.c_str(), measured ? *measured : NAN, *recovered,
                measured ? std::abs(*recovered - *measured) / *measured : NAN);
    std::fflush(stdout);
  }
}

}  // namespace collision_response

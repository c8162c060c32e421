#include "collision_response/ros/scene_player.h"

#include <geometry_msgs/TransformStamped.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ros/conversions.h"
#include "collision_response/ros/parameters.h"
#include "collision_response/ros/scene_loader.h"

namespace collision_response {
namespace {

core::Expected<std::vector<MovingFrame>> loadFrames(const XmlRpc::XmlRpcValue& list,
                                                    const std::string& field,
                                                    const std::string& fixed_frame) {
  if (auto status = checkArray(list, field); !status) return status.error();
  std::vector<MovingFrame> frames;
  for (int i = 0; i < list.size(); ++i) {
    const std::string entry_field = indexKey(field, static_cast<std::size_t>(i));
    const XmlRpc::XmlRpcValue& entry = list[i];
    if (auto status = checkKeys(entry, {"frame", "parent", "position", "velocity"}, entry_field);
        !status) {
      return status.error();
    }
    if (!entry.hasMember("frame")) return core::Error{joinKey(entry_field, "frame"), "is required"};
    MovingFrame frame;
    frame.parent = fixed_frame;
    auto name = readString(entry["frame"], joinKey(entry_field, "frame"));
    if (!name) return name.error();
    frame.frame = *name;
    if (entry.hasMember("parent")) {
      auto parent = readString(entry["parent"], joinKey(entry_field, "parent"));
      if (!parent) return parent.error();
      frame.parent = *parent;
    }
    for (const auto& [key, target] :
         {std::pair<const char*, Eigen::Vector3d*>{"position", &frame.position},
          std::pair<const char*, Eigen::Vector3d*>{"velocity", &frame.velocity}}) {
      if (!entry.hasMember(key)) continue;
      auto value = readVector3(entry[key], joinKey(entry_field, key));
      if (!value) return value.error();
      if (!value->allFinite()) {
        return core::Error{joinKey(entry_field, key), "must be finite"};
      }
      *target = *value;
    }
    frames.push_back(frame);
  }
  return frames;
}

}  // namespace

ScenePlayer::ScenePlayer(const ros::NodeHandle& node, const ros::NodeHandle& private_node)
    : node_(node), private_node_(private_node) {}

bool ScenePlayer::initialize() {
  const std::string scene_key = private_node_.resolveName("scene");
  XmlRpc::XmlRpcValue scene_value;
  if (!private_node_.getParam("scene", scene_value)) {
    ROS_FATAL_STREAM("scene_player: " << scene_key << " is required (load a scene file)");
    return false;
  }
  auto scene = loadScene(scene_value, scene_key);
  if (!scene) {
    ROS_FATAL_STREAM("scene_player: bad scene: " << scene.error().message());
    return false;
  }
  scene_ = std::move(scene.value());
  XmlRpc::XmlRpcValue frames_value;
  if (private_node_.getParam("player/frames", frames_value)) {
    auto frames =
        loadFrames(frames_value, private_node_.resolveName("player/frames"), scene_.fixed_frame);
    if (!frames) {
      ROS_FATAL_STREAM("scene_player: " << frames.error().message());
      return false;
    }
    frames_ = std::move(frames.value());
  }
  private_node_.param("rate", rate_, rate_);
  private_node_.param("duration", duration_, duration_);
  private_node_.param("start_delay", start_delay_, start_delay_);
  private_node_.param("contact_tolerance", contact_tolerance_, contact_tolerance_);
  private_node_.param("report_restitution", report_restitution_, report_restitution_);
  if (!(std::isfinite(contact_tolerance_) && contact_tolerance_ >= 0)) {
    ROS_FATAL_STREAM("scene_player: ~contact_tolerance must be a finite number >= 0");
    return false;
  }
  if (!(std::isfinite(rate_) && rate_ > 0)) {
    ROS_FATAL_STREAM("scene_player: " << private_node_.resolveName("rate")
                                      << ": must be > 0 Hz, got " << rate_);
    return false;
  }
  if (!(std::isfinite(duration_) && duration_ >= 0) ||
      !(std::isfinite(start_delay_) && start_delay_ >= 0)) {
    ROS_FATAL_STREAM("scene_player: ~duration and ~start_delay must be finite numbers >= 0 s");
    return false;
  }

  ROS_INFO_STREAM("scene_player: " << scene_.bodies.size() << " bodies at " << rate_
                                   << " Hz, duration " << duration_ << " s (0: until stopped), "
                                   << frames_.size() << " moving frames");

  state_publisher_ = node_.advertise<BodyStateArray>("body_states", 100);
  apex_publisher_ = node_.advertise<BodyState>("apexes", 100);
  impact_subscriber_ = node_.subscribe("impacts", 100, &ScenePlayer::onImpacts, this);
  created_ = ros::Time::now();
  timer_ = node_.createTimer(ros::Duration(1.0 / rate_), &ScenePlayer::onTimer, this);
  return true;
}

void ScenePlayer::onTimer(const ros::TimerEvent& event) {
  const ros::Time now = event.current_real;
  if (!playback_) {
    // Start once the monitor listens and the start delay is over (so a printer can connect).
    if ((now - created_).toSec() < start_delay_ || state_publisher_.getNumSubscribers() == 0) {
      return;
    }
    start_ = now;
    playback_ = std::make_unique<core::Playback>(scene_, contact_tolerance_, 0.0);
  }
  if (duration_ > 0 && (now - start_).toSec() > duration_) {
    ROS_INFO_STREAM("scene_player: " << duration_ << " s played; stopping");
    ros::shutdown();
    return;
  }
  publishStates(now);
  publishApexes(now);
}

void ScenePlayer::publishStates(const ros::Time& time) {
  for (const MovingFrame& frame : frames_) {
    geometry_msgs::TransformStamped transform;
    transform.header.stamp = time;
    transform.header.frame_id = frame.parent;
    transform.child_frame_id = frame.frame;
    const Eigen::Vector3d position = frame.position + frame.velocity * (time - start_).toSec();
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
    state.pose.orientation.w = 1.0;
    state.twist.linear = toVector3Msg(playback_->velocity(i, t));
    array.states.push_back(state);
  }
  state_publisher_.publish(array);
}

void ScenePlayer::onImpacts(const ImpactArray::ConstPtr& message) {
  if (!playback_) return;
  // The body's centre at the instant of impact: in continuous detection the contact point is
  // exact (the surfaces touch there), so the centre is one radius back along the normal; the
  // stamp is rounded to the nanosecond and the motion is not replayed from it. In discrete
  // detection the bodies overlap at the sample: the centre is where the player had it.
  const bool exact_contact = scene_.detection == core::Detection::kContinuous;
  for (const Impact& impact : message->impacts) {
    const Eigen::Vector3d contact = toEigen(impact.contact_point);
    const Eigen::Vector3d normal = toEigen(impact.normal);
    const double t = sinceStart(impact.header.stamp);
    for (const auto& [id, side, after] :
         {std::make_tuple(impact.body_a, -1.0, toEigen(impact.velocity_a_after.linear)),
          std::make_tuple(impact.body_b, +1.0, toEigen(impact.velocity_b_after.linear))}) {
      const auto body = playback_->bodyIndex(id);
      if (!body) continue;  // an obstacle
      const Eigen::Vector3d centre =
          exact_contact ? Eigen::Vector3d(contact + side * scene_.bodies[*body].radius * normal)
                        : playback_->position(*body, t);
      if (!playback_->applyImpact(*body, t, centre, after)) {
        ROS_WARN_STREAM_THROTTLE(1.0, "scene_player: ignored an impact on '"
                                          << id << "' older than its last applied one");
      }
    }
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
    state.pose.orientation.w = 1.0;
    state.twist.linear = toVector3Msg(apex.velocity);
    apex_publisher_.publish(state);
    if (!report_restitution_ || apex.impacts_before != 1) continue;
    // The seed's method: dropped from rest, e = sqrt(h'/h), heights of the lowest point above
    // the first plane obstacle (the floor), the drop's from the scene's initial position.
    const auto floor = std::find_if(
        scene_.obstacles.begin(), scene_.obstacles.end(), [](const core::ObstacleSpec& o) {
          return o.shape == core::ObstacleShape::kPlane && o.frame.empty();
        });
    if (floor == scene_.obstacles.end()) continue;
    const Eigen::Vector3d normal = floor->normal.normalized();
    const double drop = normal.dot(body.position) - floor->offset - body.radius;
    const double bounce = normal.dot(apex.position) - floor->offset - body.radius;
    const auto measured = scene_.materials.restitution(body.material, floor->material);
    const double recovered = std::sqrt(bounce / drop);
    std::printf("restitution %-26s table %.3f  recovered %.15f  relative error %.1e\n",
                body.material.c_str(), measured ? *measured : NAN, recovered,
                measured ? std::abs(recovered - *measured) / *measured : NAN);
    std::fflush(stdout);
  }
}

}  // namespace collision_response

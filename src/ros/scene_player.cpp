#include "collision_response/ros/scene_player.h"

#include <geometry_msgs/TransformStamped.h>

#include <cmath>
#include <cstdio>

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
  for (const core::BodySpec& body : scene_.bodies) {
    radius_[body.id] = body.radius;
    body_spec_[body.id] = &body;
  }
  if (scene_.effects.gravity) gravity_ = scene_.gravity;
  for (const core::ObstacleSpec& obstacle : scene_.obstacles) {
    if (obstacle.shape != core::ObstacleShape::kPlane || !obstacle.frame.empty()) continue;
    fixed_planes_.push_back(core::Plane{obstacle.normal.normalized(), obstacle.offset});
    fixed_plane_material_.push_back(obstacle.material);
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

ScenePlayer::Segment ScenePlayer::makeSegment(const core::BodySpec& body, const ros::Time& start,
                                              const Eigen::Vector3d& position,
                                              const Eigen::Vector3d& velocity) const {
  Segment segment{start, position, velocity, Eigen::Vector3d::Zero(), false};
  if (std::isinf(body.mass) || gravity_ == Eigen::Vector3d::Zero()) return segment;
  segment.acceleration = gravity_;
  const auto plane = core::restingPlane(position, velocity, body.radius, fixed_planes_, gravity_,
                                        contact_tolerance_);
  if (plane) {
    const Eigen::Vector3d& normal = fixed_planes_[*plane].normal;
    segment.velocity -= segment.velocity.dot(normal) * normal;
    segment.acceleration = core::restingAcceleration(gravity_, normal);
    segment.apex_published = true;  // a slide has no apex
  }
  return segment;
}

Eigen::Vector3d ScenePlayer::positionAt(const Segment& segment, const ros::Time& time) const {
  return core::positionAfter(segment.position, segment.velocity, segment.acceleration,
                             (time - segment.start).toSec());
}

Eigen::Vector3d ScenePlayer::velocityAt(const Segment& segment, const ros::Time& time) const {
  return core::velocityAfter(segment.velocity, segment.acceleration,
                             (time - segment.start).toSec());
}

void ScenePlayer::onTimer(const ros::TimerEvent& event) {
  const ros::Time now = event.current_real;
  if (!started_) {
    // Start once the monitor listens and the start delay is over (so a printer can connect).
    if ((now - created_).toSec() < start_delay_ || state_publisher_.getNumSubscribers() == 0) {
      return;
    }
    started_ = true;
    start_ = now;
    for (const core::BodySpec& body : scene_.bodies) {
      segments_[body.id] = makeSegment(body, start_, body.position, body.velocity);
    }
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
  for (const core::BodySpec& body : scene_.bodies) {
    const Segment& segment = segments_.at(body.id);
    BodyState state;
    state.header = array.header;
    state.id = body.id;
    state.pose.position = toPointMsg(positionAt(segment, time));
    state.pose.orientation.w = 1.0;
    state.twist.linear = toVector3Msg(velocityAt(segment, time));
    array.states.push_back(state);
  }
  state_publisher_.publish(array);
}

void ScenePlayer::onImpacts(const ImpactArray::ConstPtr& message) {
  for (const Impact& impact : message->impacts) {
    const Eigen::Vector3d contact = toEigen(impact.contact_point);
    const Eigen::Vector3d normal = toEigen(impact.normal);
    // The body's centre at the instant of impact: in continuous detection the contact point is
    // exact (the surfaces touch there), so the centre is one radius back along the normal; the
    // stamp is rounded to the nanosecond and the motion is not replayed from it. In discrete
    // detection the bodies overlap at the sample: the centre is where the player had it.
    const bool exact_contact = scene_.detection == core::Detection::kContinuous;
    if (radius_.count(impact.body_a) != 0) {
      const Eigen::Vector3d centre =
          exact_contact ? Eigen::Vector3d(contact - radius_[impact.body_a] * normal)
                        : positionAt(segments_.at(impact.body_a), impact.header.stamp);
      applyImpact(impact.body_a, impact.header.stamp, centre,
                  toEigen(impact.velocity_a_after.linear));
    }
    if (radius_.count(impact.body_b) != 0) {
      const Eigen::Vector3d centre =
          exact_contact ? Eigen::Vector3d(contact + radius_[impact.body_b] * normal)
                        : positionAt(segments_.at(impact.body_b), impact.header.stamp);
      applyImpact(impact.body_b, impact.header.stamp, centre,
                  toEigen(impact.velocity_b_after.linear));
    }
  }
}

void ScenePlayer::applyImpact(const std::string& id, const ros::Time& stamp,
                              const Eigen::Vector3d& centre,
                              const Eigen::Vector3d& velocity_after) {
  if (!started_) return;
  Segment& segment = segments_.at(id);
  if (stamp < segment.start) {
    ROS_WARN_STREAM_THROTTLE(
        1.0, "scene_player: ignored an impact on '" << id << "' older than its last applied one");
    return;
  }
  segment = makeSegment(*body_spec_.at(id), stamp, centre, velocity_after);
  ++bounces_[id];
}

void ScenePlayer::publishApexes(const ros::Time& time) {
  const double g = gravity_.norm();
  if (!(g > 0)) return;
  const Eigen::Vector3d up = -gravity_ / g;
  for (auto& [id, segment] : segments_) {
    const double rising = segment.velocity.dot(up);
    if (segment.apex_published || !(rising > 0)) continue;
    const ros::Time apex_time = segment.start + ros::Duration(rising / g);
    if (apex_time > time) continue;
    segment.apex_published = true;
    // The closed form, not the sample: v.up / g after the segment's start.
    const Eigen::Vector3d apex = positionAt(segment, apex_time);
    BodyState state;
    state.header.stamp = apex_time;
    state.header.frame_id = scene_.fixed_frame;
    state.id = id;
    state.pose.position = toPointMsg(apex);
    state.pose.orientation.w = 1.0;
    state.twist.linear = toVector3Msg(velocityAt(segment, apex_time));
    apex_publisher_.publish(state);
    if (!report_restitution_ || bounces_[id] != 1 || fixed_planes_.empty()) continue;
    // The seed's method: dropped from rest, e = sqrt(h'/h), heights of the lowest point above
    // the first fixed plane (the floor), the drop's from the scene's initial position.
    const core::BodySpec& body = *body_spec_.at(id);
    const core::Plane& floor = fixed_planes_.front();
    const double drop = floor.normal.dot(body.position) - floor.offset - body.radius;
    const double bounce = floor.normal.dot(apex) - floor.offset - body.radius;
    const auto measured =
        scene_.materials.restitution(body.material, fixed_plane_material_.front());
    const double recovered = std::sqrt(bounce / drop);
    std::printf("restitution %-26s table %.3f  recovered %.15f  relative error %.1e\n",
                body.material.c_str(), measured ? *measured : NAN, recovered,
                measured ? std::abs(recovered - *measured) / *measured : NAN);
    std::fflush(stdout);
  }
}

}  // namespace collision_response

// body_tracker: the robot's half of collision_response in C++, as examples/body_tracker.py (its
// comment says more). It publishes the states of the bodies it tracks, one stamped
// BodyStateArray per frame in its camera's tf frame, and applies each impact heard on `impacts`
// from the instant of impact. The tracker is a stand-in: bodies moving in straight lines from
// ~bodies (id, position, velocity in the camera frame). ~camera_pose [x, y, z, qx, qy, qz, qw]
// in ~camera_parent (default world) is broadcast as a static transform; a robot whose tf tree
// has its camera leaves it out.
//   rosrun collision_response body_tracker _bodies:="[{id: ball, position: [0, 0, 0], velocity: [1,
//   0, 0]}]"
#include <ros/ros.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/ImpactArray.h"

namespace {

// A tracked body: a straight line from (stamp, position, velocity), in the camera frame.
struct TrackedBody {
  ros::Time stamp;
  Eigen::Vector3d position;
  Eigen::Vector3d velocity;
  Eigen::Vector3d positionAt(const ros::Time& t) const {
    return position + velocity * (t - stamp).toSec();
  }
};

Eigen::Vector3d readVector(XmlRpc::XmlRpcValue& value, const std::string& name) {
  if (value.getType() != XmlRpc::XmlRpcValue::TypeArray || value.size() != 3) {
    throw std::runtime_error(name + ": must be a list of 3 numbers");
  }
  Eigen::Vector3d vector;
  for (int i = 0; i < 3; ++i) {
    const auto type = value[i].getType();
    if (type == XmlRpc::XmlRpcValue::TypeInt) {
      vector[i] = static_cast<int>(value[i]);
    } else if (type == XmlRpc::XmlRpcValue::TypeDouble &&
               std::isfinite(static_cast<double>(value[i]))) {
      vector[i] = static_cast<double>(value[i]);
    } else {
      throw std::runtime_error(name + ": must be a list of 3 finite numbers");
    }
  }
  return vector;
}

class BodyTracker {
 public:
  BodyTracker(ros::NodeHandle& node, ros::NodeHandle& private_node) : listener_(buffer_) {
    camera_frame_ = private_node.param<std::string>("camera_frame", "camera");
    transform_timeout_ = ros::Duration(private_node.param("transform_timeout", 0.5));
    const double rate = private_node.param("rate", 30.0);
    if (!(rate > 0.0)) {
      throw std::runtime_error(private_node.resolveName("rate") + ": must be > 0 Hz");
    }
    const ros::Time start = ros::Time::now();
    XmlRpc::XmlRpcValue bodies;
    const std::string key = private_node.resolveName("bodies");
    if (!private_node.getParam("bodies", bodies) ||
        bodies.getType() != XmlRpc::XmlRpcValue::TypeArray) {
      throw std::runtime_error(key + ": is required (a list of {id, position, velocity})");
    }
    for (int i = 0; i < bodies.size(); ++i) {
      const std::string entry = key + "[" + std::to_string(i) + "]";
      if (bodies[i].getType() != XmlRpc::XmlRpcValue::TypeStruct || !bodies[i].hasMember("id") ||
          bodies[i]["id"].getType() != XmlRpc::XmlRpcValue::TypeString) {
        throw std::runtime_error(entry + "/id: is required (a body id of the scene)");
      }
      tracked_[static_cast<std::string>(bodies[i]["id"])] = TrackedBody{
          start, readVector(bodies[i]["position"], entry + "/position"),
          bodies[i].hasMember("velocity") ? readVector(bodies[i]["velocity"], entry + "/velocity")
                                          : Eigen::Vector3d::Zero()};
    }
    std::vector<double> pose;
    if (private_node.getParam("camera_pose", pose)) {
      if (pose.size() != 7) {
        throw std::runtime_error(private_node.resolveName("camera_pose") +
                                 ": must be [x, y, z, qx, qy, qz, qw]");
      }
      geometry_msgs::TransformStamped camera;
      camera.header.stamp = start;
      camera.header.frame_id = private_node.param<std::string>("camera_parent", "world");
      camera.child_frame_id = camera_frame_;
      camera.transform.translation.x = pose[0];
      camera.transform.translation.y = pose[1];
      camera.transform.translation.z = pose[2];
      camera.transform.rotation.x = pose[3];
      camera.transform.rotation.y = pose[4];
      camera.transform.rotation.z = pose[5];
      camera.transform.rotation.w = pose[6];
      broadcaster_.sendTransform(camera);
    }
    publisher_ = node.advertise<collision_response::BodyStateArray>("body_states", 10);
    subscriber_ = node.subscribe("impacts", 100, &BodyTracker::applyImpacts, this);
    timer_ = node.createTimer(ros::Duration(1.0 / rate), &BodyTracker::publishStates, this);
  }

 private:
  // One frame of the tracker: every body's state at this instant, in the camera frame.
  void publishStates(const ros::TimerEvent&) {
    collision_response::BodyStateArray message;
    message.header.stamp = ros::Time::now();
    message.header.frame_id = camera_frame_;
    for (const auto& [id, body] : tracked_) {
      collision_response::BodyState state;
      state.header = message.header;
      state.id = id;
      state.pose.position = tf2::toMsg(body.positionAt(message.header.stamp));
      state.pose.orientation.w = 1.0;
      tf2::toMsg(body.velocity, state.twist.linear);
      message.states.push_back(state);
    }
    publisher_.publish(message);
  }

  // Each impact, in order: the tracked bodies it names go on from where they were at the
  // instant of impact with their velocity after, turned from the impact's frame into the camera's.
  void applyImpacts(const collision_response::ImpactArray::ConstPtr& message) {
    for (const auto& impact : message->impacts) {
      for (const auto& [id, after] :
           {std::make_pair(impact.body_a, impact.velocity_a_after.linear),
            std::make_pair(impact.body_b, impact.velocity_b_after.linear)}) {
        if (tracked_.count(id) == 0) continue;  // an obstacle, or a body another source tracks
        Eigen::Isometry3d to_camera;
        try {
          to_camera = tf2::transformToEigen(buffer_.lookupTransform(
              camera_frame_, impact.header.frame_id, impact.header.stamp, transform_timeout_));
        } catch (const tf2::TransformException& error) {
          ROS_WARN_STREAM_THROTTLE(
              1.0, "body_tracker: impact of '" << id << "' not applied: " << error.what());
          continue;
        }
        Eigen::Vector3d velocity;
        tf2::fromMsg(after, velocity);
        TrackedBody& body = tracked_[id];
        body.position = body.positionAt(impact.header.stamp);
        body.stamp = impact.header.stamp;
        body.velocity = to_camera.linear() * velocity;  // a vector turns by the rotation alone
        ROS_INFO(
            "body_tracker: %s after its impact at %.6f s: velocity (%.6g, %.6g, %.6g) m/s in %s",
            id.c_str(), impact.header.stamp.toSec(), body.velocity.x(), body.velocity.y(),
            body.velocity.z(), camera_frame_.c_str());
      }
    }
  }

  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_;
  tf2_ros::StaticTransformBroadcaster broadcaster_;
  std::string camera_frame_;
  ros::Duration transform_timeout_;
  std::map<std::string, TrackedBody> tracked_;
  ros::Publisher publisher_;
  ros::Subscriber subscriber_;
  ros::Timer timer_;  // ros::spin() runs one callback at a time: no lock needed
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "body_tracker");
  ros::NodeHandle node;
  ros::NodeHandle private_node("~");
  try {
    BodyTracker tracker(node, private_node);
    ros::spin();
  } catch (const std::runtime_error& error) {
    ROS_FATAL_STREAM("body_tracker: " << error.what());
    return 1;
  }
  return 0;
}

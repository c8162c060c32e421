// What the scene rostests that check played states and contacts against closed forms share
// (box_chute.test, box_corner.test): every body state, contact and impact the scene player and the
// node publish over real topics, timed from the first state heard.
#pragma once

#include <ros/ros.h>

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "collision_response/BodyStateArray.h"
#include "collision_response/Contact.h"
#include "collision_response/ContactArray.h"
#include "collision_response/ImpactArray.h"

namespace collision_response::testing {

inline Eigen::Vector3d vec(const geometry_msgs::Point& p) { return {p.x, p.y, p.z}; }
inline Eigen::Vector3d vec(const geometry_msgs::Vector3& v) { return {v.x, v.y, v.z}; }

/// Listens on body_states, contacts and impacts from construction.
class PlayedScene {
 public:
  struct State {
    double time;  ///< s from the first state heard
    Eigen::Vector3d position, velocity;
  };
  /// One contacts message's contacts of one body.
  struct Contacts {
    double time;
    std::vector<collision_response::Contact> contacts;
  };

  explicit PlayedScene(ros::NodeHandle& node) {
    state_sub_ = node.subscribe<collision_response::BodyStateArray>(
        "body_states", 1000, [this](const collision_response::BodyStateArray::ConstPtr& array) {
          if (start_.isZero()) start_ = array->header.stamp;
          const double t = (array->header.stamp - start_).toSec();
          for (const auto& state : array->states) {
            if (t == 0.0) first[state.id] = vec(state.pose.position);
            states[state.id].push_back({t, vec(state.pose.position), vec(state.twist.linear)});
          }
        });
    contact_sub_ = node.subscribe<collision_response::ContactArray>(
        "contacts", 1000, [this](const collision_response::ContactArray::ConstPtr& array) {
          if (start_.isZero() || array->contacts.empty()) return;
          const double t = (array->header.stamp - start_).toSec();
          std::map<std::string, Contacts> now;
          for (const auto& contact : array->contacts) {
            now[contact.body_a].time = t;
            now[contact.body_a].contacts.push_back(contact);
          }
          for (const auto& [body, c] : now) contacts[body].push_back(c);
        });
    impact_sub_ = node.subscribe<collision_response::ImpactArray>(
        "impacts", 100, [this](const collision_response::ImpactArray::ConstPtr& array) {
          impacts += array->impacts.size();
        });
  }

  /// Spins until each of `bodies` has states and contacts heard at `until` s or later, or
  /// `wall_seconds` of wall time have passed.
  void waitFor(const std::vector<std::string>& bodies, double until, double wall_seconds) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(wall_seconds);
    const auto heard_all = [&] {
      for (const std::string& body : bodies) {
        if (states[body].empty() || states[body].back().time < until || contacts[body].empty() ||
            contacts[body].back().time < until) {
          return false;
        }
      }
      return true;
    };
    while (ros::ok() && ros::WallTime::now() < end && !heard_all()) {
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
  }

  std::map<std::string, Eigen::Vector3d> first;  ///< each body's state at 0 (the scene's first)
  std::map<std::string, std::vector<State>> states;
  std::map<std::string, std::vector<Contacts>> contacts;  ///< per body_a
  std::size_t impacts = 0;

 private:
  ros::Time start_;
  ros::Subscriber state_sub_, contact_sub_, impact_sub_;
};

}  // namespace collision_response::testing

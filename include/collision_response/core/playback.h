// Playing a scene without ROS: bodies moved in closed form from their initial states, impacts
// applied from their instants. The scene player (ROS) and the accuracy benchmark both use it.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "collision_response/core/monitor.h"
#include "collision_response/core/motion.h"
#include "collision_response/core/scene.h"

namespace collision_response::core {

/// One flight's highest point (against gravity).
struct Apex {
  std::size_t body = 0;  ///< index into the scene's bodies (as listed)
  double time = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  int impacts_before = 0;  ///< impacts the body had before this flight
};

class Playback {
 public:
  /// Starts every body of `scene` at `start` from its `position` and `velocity`.
  Playback(const Scene& scene, double contact_tolerance, double start);

  std::size_t bodyCount() const { return segments_.size(); }
  Eigen::Vector3d position(std::size_t body, double time) const;
  Eigen::Vector3d velocity(std::size_t body, double time) const;

  /// An impact the monitor reported on `body` at `time`: from then on it moves from `centre`
  /// at `velocity_after` (resting on a fixed plane when it touches one slowly). Impacts older
  /// than the body's current motion are ignored (false).
  bool applyImpact(std::size_t body, double time, const Eigen::Vector3d& centre,
                   const Eigen::Vector3d& velocity_after);

  /// Applies an impact record of `monitor` (whose bodies are indexed by id) to the bodies it
  /// names, placing them at the contact (`exact_contact`: continuous detection, where the
  /// surfaces touch there) or where they were.
  void applyImpact(const ImpactMonitor& monitor, const ImpactRecord& impact, bool exact_contact);

  /// The flights whose highest point is at or before `time` and not yet reported.
  std::vector<Apex> apexesUntil(double time);

  std::optional<std::size_t> bodyIndex(const std::string& id) const;

 private:
  struct Segment {
    double start = 0.0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
    bool apex_reported = false;
    int impacts_before = 0;
  };
  Segment makeSegment(std::size_t body, double start, const Eigen::Vector3d& position,
                      const Eigen::Vector3d& velocity, int impacts_before) const;

  Scene scene_;
  double contact_tolerance_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();
  std::vector<Plane> fixed_planes_;
  std::vector<Segment> segments_;
  std::map<std::string, std::size_t> index_;
};

}  // namespace collision_response::core

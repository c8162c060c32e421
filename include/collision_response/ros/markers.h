// rviz markers of the monitor's scene: bodies, obstacles, impacts and contact points, and the
// lasting contacts with their normal forces.
#pragma once

#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <string>

#include "collision_response/ContactArray.h"
#include "collision_response/Impact.h"
#include "collision_response/core/monitor.h"
#include "collision_response/core/scene.h"

namespace collision_response {

/// What the markers look like: `~markers/...` parameters.
struct MarkerParams {
  double rate = 30.0;              ///< Hz: bodies and obstacles at most this often
  double impact_lifetime = 0.5;    ///< s: how long an impact's arrow and contact point stay
  double impulse_scale = 0.2;      ///< m per N s: an impact's arrow length per unit impulse
  double force_scale = 0.02;       ///< m per N: a lasting contact's arrow length per unit force
  double plane_size = 4.0;         ///< m: the side of the square drawn for a plane obstacle
  double contact_diameter = 0.02;  ///< m: the sphere drawn at a contact point
};

/// Marker namespaces. Ids are stable: a body's and an obstacle's is its index among the
/// scene's bodies (obstacles) sorted by id; impacts count up and wrap at kImpactIds; a lasting
/// contact's is its index in the `contacts` array drawn.
inline constexpr const char* kBodiesNamespace = "bodies";
inline constexpr const char* kObstaclesNamespace = "obstacles";
inline constexpr const char* kObstacleEndsNamespace = "obstacle_ends";
inline constexpr const char* kBodyEndsNamespace = "body_ends";
inline constexpr const char* kImpactsNamespace = "impacts";
inline constexpr const char* kContactsNamespace = "contacts";
inline constexpr const char* kLastingContactsNamespace = "lasting_contacts";
inline constexpr const char* kContactForcesNamespace = "contact_forces";
inline constexpr int kImpactIds = 10000;

/// The colour of a material: the seed's materials have their own; any other material a
/// colour from its name (the same name, the same colour, in every run).
std_msgs::ColorRGBA materialColour(const std::string& material);

/// Where a body is: its centre (of mass) and its orientation (world from body).
struct BodyPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// A body as its shape where `pose` puts it (id `index`, namespace `bodies`), as an obstacle of
/// that shape is drawn (appendObstacleMarkers): a sphere (a ball unturned, whatever its
/// orientation); a box as a CUBE of its edges and a cylinder as a CYLINDER, turned by the
/// orientation; a capsule as a CYLINDER (its segment) and its two ends as a SPHERE_LIST in
/// `body_ends`; a mesh body as its resource. Not tracked (`pose` empty): their deletion.
void appendBodyMarkers(const core::BodySpec& body, int index, const std::optional<BodyPose>& pose,
                       const std::string& frame, const ros::Time& stamp,
                       visualization_msgs::MarkerArray& array);

/// An obstacle where `placed` puts it (in `frame`), with id `index`: a sphere; a plane as a thin
/// square of side `plane_size` centred on the plane's point nearest the origin with its normal;
/// a box as a cube, a cylinder as a cylinder, both turned with the obstacle; a capsule as a
/// cylinder (its segment) and its two ends as a sphere list in `kObstacleEndsNamespace`.
void appendObstacleMarkers(const core::ObstacleSpec& obstacle, int index,
                           const core::PlacedShape& placed, const std::string& frame,
                           const ros::Time& stamp, const MarkerParams& params,
                           visualization_msgs::MarkerArray& array);

/// An impact: an arrow from the contact point along the normal (towards body_b, the direction
/// of the impulse on body_b), impulse_scale m per N s long, and a sphere at the contact point;
/// both with id `id` in their namespaces and the lifetime `impact_lifetime`.
void appendImpactMarkers(const Impact& impact, int id, const MarkerParams& params,
                         visualization_msgs::MarkerArray& array);

/// The lasting contacts of `contacts`: a sphere at each contact point (namespace
/// lasting_contacts) and an arrow from it along the normal (towards body_b, the direction of the
/// normal force on body_b), force_scale m per N long (contact_forces), both with id = the
/// contact's index and no lifetime; the ids from contacts.size() up to `drawn_before` (those of
/// contacts that ended) deleted in both namespaces.
void appendContactMarkers(const ContactArray& contacts, std::size_t drawn_before,
                          const MarkerParams& params, visualization_msgs::MarkerArray& array);

/// The monitor's bodies (where it predicts them at `time`; deleted while not tracked) and its
/// placed obstacles, appended to `array`.
void appendSceneMarkers(const core::ImpactMonitor& monitor, double time, const std::string& frame,
                        const ros::Time& stamp, const MarkerParams& params,
                        visualization_msgs::MarkerArray& array);

}  // namespace collision_response

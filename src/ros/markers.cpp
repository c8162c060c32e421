#include "collision_response/ros/markers.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <type_traits>
#include <variant>

#include "collision_response/core/body_shape.h"
#include "collision_response/core/triangle_mesh.h"
#include "collision_response/ros/conversions.h"

namespace collision_response {
namespace {

std_msgs::ColorRGBA rgba(float r, float g, float b, float a = 1.0f) {
  std_msgs::ColorRGBA colour;
  colour.r = r;
  colour.g = g;
  colour.b = b;
  colour.a = a;
  return colour;
}

/// A bright colour from a hue in [0, 1) (HSV with full saturation and value).
std_msgs::ColorRGBA fromHue(double hue) {
  const double h = 6.0 * (hue - std::floor(hue));
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  const std::array<std::array<double, 3>, 6> sectors = {
      {{1, x, 0}, {x, 1, 0}, {0, 1, x}, {0, x, 1}, {x, 0, 1}, {1, 0, x}}};
  const auto& rgb = sectors[static_cast<std::size_t>(h) % 6];
  return rgba(static_cast<float>(rgb[0]), static_cast<float>(rgb[1]), static_cast<float>(rgb[2]));
}

visualization_msgs::Marker base(const std::string& ns, int id, int type, const std::string& frame,
                                const ros::Time& stamp) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame;
  marker.header.stamp = stamp;
  marker.ns = ns;
  marker.id = id;
  marker.type = type;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  return marker;
}

}  // namespace

std_msgs::ColorRGBA materialColour(const std::string& material) {
  // The seed's balls in colours that recall them; the reference surface grey.
  static const std::map<std::string, std_msgs::ColorRGBA> known = {
      {"concrete", rgba(0.6f, 0.6f, 0.6f)},
      {"range_golf_ball", rgba(1.0f, 1.0f, 1.0f)},
      {"tennis_ball", rgba(0.8f, 1.0f, 0.0f)},
      {"billiard_ball", rgba(0.9f, 0.1f, 0.1f)},
      {"hand_ball", rgba(1.0f, 0.5f, 0.0f)},
      {"wooden_ball", rgba(0.6f, 0.4f, 0.2f)},
      {"steel_ball_bearing", rgba(0.75f, 0.8f, 0.85f)},
      {"glass_marble", rgba(0.3f, 0.7f, 1.0f)},
      {"rubber_band_ball", rgba(0.9f, 0.2f, 0.7f)},
      {"hollow_hard_plastic_ball", rgba(0.2f, 0.8f, 0.3f)},
  };
  const auto found = known.find(material);
  if (found != known.end()) return found->second;
  std::uint32_t hash = 2166136261u;  // FNV-1a of the name: the same in every run
  for (const char c : material) hash = (hash ^ static_cast<unsigned char>(c)) * 16777619u;
  return fromHue(static_cast<double>(hash % 360u) / 360.0);
}

namespace {

void setPose(visualization_msgs::Marker& marker, const Eigen::Vector3d& position,
             const Eigen::Quaterniond& orientation) {
  marker.pose.position = toPointMsg(position);
  marker.pose.orientation = toQuaternionMsg(orientation);
}

/// What a shape's markers carry besides the shape: their namespaces (the shape's, and its
/// capsule ends'), id, frame, stamp, colour and text, and a mesh's resource and scale.
struct ShapeLook {
  const char* ns = kObstaclesNamespace;
  const char* ends_ns = kObstacleEndsNamespace;
  int index = 0;
  std::string frame;
  ros::Time stamp;
  std_msgs::ColorRGBA colour;
  std::string text;
  std::string resource;
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
};

/// A shape drawn where `centre` and `axes` (fixed <- the shape's frame) put it: a sphere about
/// `centre` plus its own centre (a body's sphere is about its frame's origin, an obstacle's is
/// given in the fixed frame with `centre` zero); a plane (in the fixed frame) as a thin square
/// of side `plane_size` centred on its point nearest the origin, its z the normal; a box as a
/// CUBE, a cylinder as a CYLINDER (rviz's is along its z, as ours), both turned by `axes`; a
/// capsule as a CYLINDER (its segment) and its two ends as a SPHERE_LIST in `look.ends_ns`; a
/// mesh as its resource (scaled), or as its triangles where it has none (built by a program).
void appendShapeMarkers(const core::Shape& shape, const Eigen::Vector3d& centre,
                        const Eigen::Quaterniond& axes, const ShapeLook& look,
                        const MarkerParams& params, visualization_msgs::MarkerArray& array) {
  const auto marker_of = [&](std::int32_t type) {
    visualization_msgs::Marker marker = base(look.ns, look.index, type, look.frame, look.stamp);
    marker.color = look.colour;
    marker.text = look.text;
    return marker;
  };
  std::optional<visualization_msgs::Marker> capsule_ends;
  visualization_msgs::Marker marker = std::visit(
      [&](const auto& kind) {
        using Kind = std::decay_t<decltype(kind)>;
        if constexpr (std::is_same_v<Kind, core::Sphere>) {
          visualization_msgs::Marker m = marker_of(visualization_msgs::Marker::SPHERE);
          setPose(m, centre + axes * kind.centre, axes);
          m.scale.x = m.scale.y = m.scale.z = 2.0 * kind.radius;
          return m;
        } else if constexpr (std::is_same_v<Kind, core::Plane>) {
          // A thin square whose z axis is the plane's normal.
          visualization_msgs::Marker m = marker_of(visualization_msgs::Marker::CUBE);
          setPose(m, Eigen::Vector3d(kind.offset * kind.normal),
                  Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(),
                                                     kind.normal.normalized()));
          m.scale.x = m.scale.y = params.plane_size;
          m.scale.z = 1e-3 * params.plane_size;
          m.color.a = 0.4f;  // see-through, so bodies behind it show
          return m;
        } else if constexpr (std::is_same_v<Kind, core::Cuboid>) {
          visualization_msgs::Marker m = marker_of(visualization_msgs::Marker::CUBE);
          setPose(m, centre, axes);
          m.scale.x = 2 * kind.half_size.x();
          m.scale.y = 2 * kind.half_size.y();
          m.scale.z = 2 * kind.half_size.z();
          return m;
        } else if constexpr (std::is_same_v<Kind, core::Mesh>) {
          // rviz loads the mesh's own resource, scaled as the scene says; a mesh built without
          // one (by a program) is drawn as its triangles.
          if (!look.resource.empty()) {
            visualization_msgs::Marker m = marker_of(visualization_msgs::Marker::MESH_RESOURCE);
            setPose(m, centre, axes);
            m.mesh_resource = look.resource;
            m.scale.x = look.scale.x();
            m.scale.y = look.scale.y();
            m.scale.z = look.scale.z();
            return m;
          }
          visualization_msgs::Marker m = marker_of(visualization_msgs::Marker::TRIANGLE_LIST);
          setPose(m, centre, axes);
          m.scale.x = m.scale.y = m.scale.z = 1.0;
          if (kind.triangles) {
            for (const core::TriangleMesh::Triangle& t : kind.triangles->triangles()) {
              for (const std::uint32_t v : t) {
                m.points.push_back(toPointMsg(kind.triangles->vertices()[v]));
              }
            }
          }
          return m;
        } else {
          // A cylinder; a capsule's segment as one, its ends as a sphere list.
          visualization_msgs::Marker m = marker_of(visualization_msgs::Marker::CYLINDER);
          setPose(m, centre, axes);
          m.scale.x = m.scale.y = 2 * kind.radius;
          m.scale.z = 2 * kind.half_length;
          if constexpr (std::is_same_v<Kind, core::Capsule>) {
            visualization_msgs::Marker ends =
                base(look.ends_ns, look.index, visualization_msgs::Marker::SPHERE_LIST, look.frame,
                     look.stamp);
            ends.color = m.color;
            const Eigen::Vector3d along = axes * Eigen::Vector3d::UnitZ();
            ends.points = {toPointMsg(Eigen::Vector3d(centre + kind.half_length * along)),
                           toPointMsg(Eigen::Vector3d(centre - kind.half_length * along))};
            ends.scale.x = ends.scale.y = ends.scale.z = 2 * kind.radius;
            ends.pose.orientation.w = 1.0;
            capsule_ends = ends;
          }
          return m;
        }
      },
      shape);
  array.markers.push_back(marker);
  if (capsule_ends) array.markers.push_back(*capsule_ends);
}

}  // namespace

void appendBodyMarkers(const core::BodySpec& body, int index, const std::optional<BodyPose>& pose,
                       const std::string& frame, const ros::Time& stamp,
                       visualization_msgs::MarkerArray& array) {
  if (!pose) {
    // Its shape's marker and, for a capsule, its ends (the ids of both namespaces are the body's).
    visualization_msgs::Marker gone =
        base(kBodiesNamespace, index, visualization_msgs::Marker::SPHERE, frame, stamp);
    gone.action = visualization_msgs::Marker::DELETE;
    array.markers.push_back(gone);
    if (body.shape == core::BodyShape::kCapsule) {
      gone.ns = kBodyEndsNamespace;
      array.markers.push_back(gone);
    }
    return;
  }
  ShapeLook look;
  look.ns = kBodiesNamespace;
  look.ends_ns = kBodyEndsNamespace;
  look.index = index;
  look.frame = frame;
  look.stamp = stamp;
  look.colour = materialColour(body.material);
  look.text = body.id;
  look.resource = body.resource;
  look.scale = body.scale;
  // A ball's orientation does not matter: it is drawn unturned (its state may not give one).
  const Eigen::Quaterniond axes =
      core::isShapedBody(body) ? pose->orientation.normalized() : Eigen::Quaterniond::Identity();
  appendShapeMarkers(core::shapeOf(body), pose->position, axes, look, MarkerParams{}, array);
}

void appendObstacleMarkers(const core::ObstacleSpec& obstacle, int index,
                           const core::PlacedShape& placed, const std::string& frame,
                           const ros::Time& stamp, const MarkerParams& params,
                           visualization_msgs::MarkerArray& array) {
  ShapeLook look;
  look.index = index;
  look.frame = frame;
  look.stamp = stamp;
  look.colour = materialColour(obstacle.material);
  look.text = obstacle.id;
  look.resource = obstacle.resource;
  look.scale = obstacle.scale;
  // A sphere and a plane are placed in the fixed frame; a finite shape in its pose's.
  const bool in_fixed_frame = std::holds_alternative<core::Sphere>(placed.shape) ||
                              std::holds_alternative<core::Plane>(placed.shape);
  appendShapeMarkers(placed.shape,
                     in_fixed_frame ? Eigen::Vector3d::Zero()
                                    : Eigen::Vector3d(placed.pose.transform.translation()),
                     in_fixed_frame ? Eigen::Quaterniond::Identity()
                                    : Eigen::Quaterniond(placed.pose.transform.linear()),
                     look, params, array);
}

void appendImpactMarkers(const Impact& impact, int id, const MarkerParams& params,
                         visualization_msgs::MarkerArray& array) {
  visualization_msgs::Marker arrow = base(kImpactsNamespace, id, visualization_msgs::Marker::ARROW,
                                          impact.header.frame_id, impact.header.stamp);
  const Eigen::Vector3d from = toEigen(impact.contact_point);
  const Eigen::Vector3d to = from + params.impulse_scale * impact.impulse * toEigen(impact.normal);
  arrow.points = {toPointMsg(from), toPointMsg(to)};
  const double shaft = 0.5 * params.contact_diameter;
  arrow.scale.x = shaft;        // shaft diameter
  arrow.scale.y = 2.0 * shaft;  // head diameter
  arrow.scale.z = 0.0;          // head length: rviz's default
  arrow.color = rgba(1.0f, 0.2f, 0.2f);
  arrow.lifetime = ros::Duration(params.impact_lifetime);
  arrow.text = impact.body_a + " -> " + impact.body_b;
  array.markers.push_back(arrow);

  visualization_msgs::Marker contact =
      base(kContactsNamespace, id, visualization_msgs::Marker::SPHERE, impact.header.frame_id,
           impact.header.stamp);
  contact.pose.position = impact.contact_point;
  contact.scale.x = contact.scale.y = contact.scale.z = params.contact_diameter;
  contact.color = rgba(1.0f, 1.0f, 0.0f);
  contact.lifetime = ros::Duration(params.impact_lifetime);
  array.markers.push_back(contact);
}

void appendContactMarkers(const ContactArray& contacts, std::size_t drawn_before,
                          const MarkerParams& params, visualization_msgs::MarkerArray& array) {
  const std::string& frame = contacts.header.frame_id;
  const ros::Time& stamp = contacts.header.stamp;
  for (std::size_t k = 0; k < contacts.contacts.size(); ++k) {
    const Contact& contact = contacts.contacts[k];
    const int id = static_cast<int>(k);
    // As an impact's arrow (appendImpactMarkers), with the force in place of the impulse.
    visualization_msgs::Marker arrow =
        base(kContactForcesNamespace, id, visualization_msgs::Marker::ARROW, frame, stamp);
    const Eigen::Vector3d from = toEigen(contact.contact_point);
    const Eigen::Vector3d to =
        from + params.force_scale * contact.normal_force * toEigen(contact.normal);
    arrow.points = {toPointMsg(from), toPointMsg(to)};
    const double shaft = 0.5 * params.contact_diameter;
    arrow.scale.x = shaft;
    arrow.scale.y = 2.0 * shaft;
    arrow.scale.z = 0.0;
    arrow.color = rgba(0.2f, 0.4f, 1.0f);
    arrow.text = contact.body_a + " -> " + contact.body_b + " (" + contact.state + ")";
    array.markers.push_back(arrow);

    visualization_msgs::Marker point =
        base(kLastingContactsNamespace, id, visualization_msgs::Marker::SPHERE, frame, stamp);
    point.pose.position = contact.contact_point;
    point.scale.x = point.scale.y = point.scale.z = params.contact_diameter;
    point.color = rgba(0.0f, 0.9f, 0.9f);
    array.markers.push_back(point);
  }
  for (std::size_t k = contacts.contacts.size(); k < drawn_before; ++k) {
    for (const char* ns : {kContactForcesNamespace, kLastingContactsNamespace}) {
      visualization_msgs::Marker gone =
          base(ns, static_cast<int>(k), visualization_msgs::Marker::SPHERE, frame, stamp);
      gone.action = visualization_msgs::Marker::DELETE;
      array.markers.push_back(gone);
    }
  }
}

void appendSceneMarkers(const core::ImpactMonitor& monitor, double time, const std::string& frame,
                        const ros::Time& stamp, const MarkerParams& params,
                        visualization_msgs::MarkerArray& array) {
  for (std::size_t i = 0; i < monitor.bodyCount(); ++i) {
    const auto state = monitor.predictedState(i, time);
    std::optional<BodyPose> pose;
    if (state) pose = BodyPose{state->first, monitor.predictedOrientation(i, time)};
    appendBodyMarkers(monitor.body(i), static_cast<int>(i), pose, frame, stamp, array);
  }
  for (std::size_t i = 0; i < monitor.obstacleCount(); ++i) {
    const auto pose = monitor.obstaclePose(i);
    if (!pose) continue;  // a tf-attached obstacle not placed yet
    appendObstacleMarkers(monitor.obstacle(i), static_cast<int>(i), *pose, frame, stamp, params,
                          array);
  }
}

}  // namespace collision_response

#include "collision_response/ros/robot_obstacles.h"

#include <urdf/model.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>

#include "collision_response/ros/mesh_resource.h"
#include "collision_response/ros/parameters.h"

namespace collision_response {

namespace {

/// A <collision> as an obstacle of the scene: false when it has no geometry; a mesh is loaded
/// (mesh_resource.h), and what that leaves out, or a padding it cannot take, is said in
/// `warnings`.
core::Expected<bool> toObstacle(const urdf::Collision& collision, const RobotLinks& robot,
                                const std::string& where, const std::string& field,
                                core::ObstacleSpec& obstacle, std::vector<std::string>& warnings) {
  const urdf::Geometry* geometry = collision.geometry.get();
  if (geometry == nullptr) return false;
  const double pad = robot.padding;
  switch (geometry->type) {
    case urdf::Geometry::SPHERE: {
      obstacle.shape = core::ObstacleShape::kSphere;
      obstacle.radius = static_cast<const urdf::Sphere*>(geometry)->radius + pad;
      break;
    }
    case urdf::Geometry::BOX: {
      const urdf::Vector3& size = static_cast<const urdf::Box*>(geometry)->dim;
      obstacle.shape = core::ObstacleShape::kBox;
      obstacle.size = Eigen::Vector3d(size.x, size.y, size.z) + Eigen::Vector3d::Constant(2 * pad);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto* cylinder = static_cast<const urdf::Cylinder*>(geometry);
      obstacle.shape = core::ObstacleShape::kCylinder;
      obstacle.radius = cylinder->radius + pad;
      obstacle.length = cylinder->length + 2 * pad;
      break;
    }
    case urdf::Geometry::MESH: {
      const auto* mesh = static_cast<const urdf::Mesh*>(geometry);
      obstacle.shape = core::ObstacleShape::kMesh;
      obstacle.resource = mesh->filename;
      obstacle.scale = Eigen::Vector3d(mesh->scale.x, mesh->scale.y, mesh->scale.z);
      std::vector<std::string> left_out;
      auto triangles = loadMeshResource(obstacle.resource, obstacle.scale, "mesh", left_out,
                                        robot.max_mesh_bytes);
      if (!triangles) {
        // Named as the URDF names it: the <mesh>'s filename or scale.
        const bool scale = triangles.error().field.rfind("mesh/scale", 0) == 0;
        return core::Error{
            joinKey(field, "description"),
            where + ", <mesh> " + (scale ? "scale" : "filename") + ": " + triangles.error().reason};
      }
      obstacle.mesh = *triangles;
      for (const std::string& warning : left_out) warnings.push_back(where + ": " + warning);
      if (pad > 0) {
        warnings.push_back(where + ": mesh '" + mesh->filename +
                           "' is not grown by the padding (only spheres, boxes and cylinders are)");
      }
      break;
    }
    default:
      return false;
  }
  const urdf::Pose& origin = collision.origin;
  obstacle.position = Eigen::Vector3d(origin.position.x, origin.position.y, origin.position.z);
  double x = 0, y = 0, z = 0, w = 1;
  origin.rotation.getQuaternion(x, y, z, w);
  obstacle.orientation = Eigen::Quaterniond(w, x, y, z).normalized();
  return true;
}

}  // namespace

core::Expected<std::vector<core::ObstacleSpec>> robotObstacles(const std::string& urdf,
                                                               const RobotLinks& robot,
                                                               const std::string& field,
                                                               std::vector<std::string>& warnings) {
  urdf::Model model;
  if (urdf.empty() || !model.initString(urdf)) {
    return core::Error{joinKey(field, "description"),
                       "the URDF in '" + robot.description +
                           "' does not parse (urdfdom's message is in the log above)"};
  }
  // In name order (the model's map), or as listed.
  std::vector<std::string> names;
  if (robot.all_links) {
    for (const auto& [name, link] : model.links_) names.push_back(name);
  } else {
    for (std::size_t i = 0; i < robot.links.size(); ++i) {
      const std::string& name = robot.links[i];
      const auto found = model.links_.find(name);
      const std::string item = indexKey(joinKey(field, "links"), i);
      if (found == model.links_.end()) {
        // Its links, in name order, so that a typo is seen at once.
        std::string known;
        for (const auto& [link_name, link] : model.links_) {
          known += (known.empty() ? "" : ", ") + link_name;
        }
        return core::Error{item, "the URDF has no link '" + name + "'; its links: " + known};
      }
      if (found->second->collision_array.empty()) {
        return core::Error{item, "link '" + name + "' has no <collision>"};
      }
      names.push_back(name);
    }
  }
  std::vector<core::ObstacleSpec> obstacles;
  for (const std::string& name : names) {
    const auto& collisions = model.links_.at(name)->collision_array;
    for (std::size_t i = 0; i < collisions.size(); ++i) {
      core::ObstacleSpec obstacle;
      obstacle.id = collisions.size() == 1 ? name : name + "/" + std::to_string(i);
      obstacle.frame = name;
      obstacle.material = robot.material;
      const std::string where = "link '" + name + "' <collision> " + std::to_string(i);
      if (!collisions[i]) {
        warnings.push_back(where + ": no geometry, not an obstacle");
        continue;
      }
      const auto made = toObstacle(*collisions[i], robot, where, field, obstacle, warnings);
      if (!made) return made.error();
      if (!*made) {
        warnings.push_back(where + ": no geometry, not an obstacle");
        continue;
      }
      obstacles.push_back(obstacle);
    }
  }
  return obstacles;
}

}  // namespace collision_response

#include "collision_response/ros/robot_obstacles.h"

#include <tinyxml2.h>
#include <urdf/model.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

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

/// The first word of `value` that is not a finite number, as urdfdom reads numbers (a `nan`, an
/// `inf`, a `1e400` past the doubles, a `0.1x`); empty when there is none.
std::string firstNonFinite(const char* value) {
  std::istringstream words(value);
  std::string word;
  while (words >> word) {
    errno = 0;
    char* end = nullptr;
    const double number = std::strtod(word.c_str(), &end);
    if (end == word.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(number)) {
      return word;
    }
  }
  return "";
}

/// Why urdfdom left out a <collision> of link `name` (issue 41, item 7: it drops every
/// <collision> of a link for one value it cannot read, with a log line only): the raw XML's
/// <collision> elements of the link (`link`, read with tinyxml2 as urdf reads the XML) are held
/// against `parsed`, urdfdom's; the first number it could not read is named. Empty when they agree.
std::string droppedCollisions(const tinyxml2::XMLElement* link, const std::string& name,
                              std::size_t parsed) {
  if (link == nullptr) return "";
  // The numbers of a <collision>: its origin's, its geometry's.
  static const std::vector<std::pair<const char*, std::vector<const char*>>> kNumbers = {
      {"origin", {"xyz", "rpy"}},         {"box", {"size"}},   {"sphere", {"radius"}},
      {"cylinder", {"radius", "length"}}, {"mesh", {"scale"}},
  };
  std::size_t raw = 0;
  for (const tinyxml2::XMLElement* collision = link->FirstChildElement("collision");
       collision != nullptr; collision = collision->NextSiblingElement("collision"), ++raw) {
    const tinyxml2::XMLElement* geometry = collision->FirstChildElement("geometry");
    for (const auto& [tag, attributes] : kNumbers) {
      const tinyxml2::XMLElement* element =
          std::string(tag) == "origin"
              ? collision->FirstChildElement(tag)
              : (geometry != nullptr ? geometry->FirstChildElement(tag) : nullptr);
      if (element == nullptr) continue;
      for (const char* attribute : attributes) {
        const char* value = element->Attribute(attribute);
        if (value == nullptr) continue;
        const std::string bad = firstNonFinite(value);
        if (bad.empty()) continue;
        return "link '" + name + "' <collision> " + std::to_string(raw) + ", <" + tag + "> " +
               attribute + "=\"" + value + "\": '" + bad +
               "' is not a finite number (urdfdom drops every <collision> of the link for it)";
      }
    }
  }
  if (raw != parsed) {
    return "link '" + name + "' has " + std::to_string(raw) + " <collision> element(s), of which " +
           "urdfdom read " + std::to_string(parsed) + " (its message is in the log above)";
  }
  return "";
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
  // The raw XML, for what urdfdom dropped (droppedCollisions): urdfdom parsed it, so does
  // tinyxml2.
  tinyxml2::XMLDocument xml;
  if (xml.Parse(urdf.c_str()) != tinyxml2::XML_SUCCESS) {
    return core::Error{joinKey(field, "description"),
                       "the URDF in '" + robot.description +
                           "' does not parse as XML, although urdfdom read it: " +
                           (xml.ErrorStr() != nullptr ? xml.ErrorStr() : "")};
  }
  std::map<std::string, const tinyxml2::XMLElement*> links_xml;
  const tinyxml2::XMLElement* robot_xml = xml.FirstChildElement("robot");
  for (const tinyxml2::XMLElement* link = robot_xml ? robot_xml->FirstChildElement("link")
                                                    : nullptr;
       link != nullptr; link = link->NextSiblingElement("link")) {
    if (const char* name = link->Attribute("name")) links_xml.emplace(name, link);
  }
  const auto dropped = [&](const std::string& name) {
    const auto link = links_xml.find(name);
    return droppedCollisions(link == links_xml.end() ? nullptr : link->second, name,
                             model.links_.at(name)->collision_array.size());
  };
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
      if (const std::string why = dropped(name); !why.empty()) {
        return core::Error{joinKey(field, "description"), why};
      }
      if (found->second->collision_array.empty()) {
        return core::Error{item, "link '" + name + "' has no <collision>"};
      }
      names.push_back(name);
    }
  }
  std::vector<core::ObstacleSpec> obstacles;
  for (const std::string& name : names) {
    // (A listed link was checked above, before its missing <collision> was.)
    if (const std::string why = robot.all_links ? dropped(name) : std::string(); !why.empty()) {
      return core::Error{joinKey(field, "description"), why};
    }
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

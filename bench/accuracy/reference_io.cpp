// The benchmark's side of the references: the scenes' inputs written out for
// reference/make_references.py, and its answers read back.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "harness.h"

namespace collision_response::bench {

void Run::record(const Play& play, double time, const std::vector<V>& p, const std::vector<V>& v) {
  bodies = p.size();
  ++states;
  if (!play.record_all && times.size() == 2) {
    times.back() = time;
    std::copy(p.begin(), p.end(), positions.end() - static_cast<std::ptrdiff_t>(bodies));
    std::copy(v.begin(), v.end(), velocities.end() - static_cast<std::ptrdiff_t>(bodies));
    return;
  }
  times.push_back(time);
  positions.insert(positions.end(), p.begin(), p.end());
  velocities.insert(velocities.end(), v.begin(), v.end());
}

namespace {

// C99 hex floats: every double exactly, read exactly by Python's float.fromhex.
std::string hex(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%a", value);
  return text;
}
std::string hex(const V& v) { return hex(v.x()) + " " + hex(v.y()) + " " + hex(v.z()); }

}  // namespace

void exportScenes(const std::vector<BenchScene>& scenes, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "# The inputs of every scene of bench/accuracy (scenes.cpp), for make_references.py.\n"
         "# Written by `accuracy_benchmark --export-scenes`; numbers are C99 hex floats (exact).\n"
         "# scene NAME duration T gravity G gx gy gz threshold S reference "
         "events|conservation|lasting\n"
         "#   friction F spin S   (1: the effect is on)\n"
         "# material NAME E MU   (E: its own coefficient, that is, against concrete; MU: its\n"
         "#   Coulomb friction against itself)\n"
         "# body ID MATERIAL MASS RADIUS px py pz vx vy vz\n"
         "# plane ID MATERIAL nx ny nz OFFSET   (free side: where n points)\n"
         "# sphere ID MATERIAL px py pz RADIUS  (an immovable sphere)\n";
  for (const BenchScene& bench : scenes) {
    std::vector<std::string> variants = {"none"};
    variants.insert(variants.end(), bench.effect_variants.begin(), bench.effect_variants.end());
    for (const std::string& effects : variants) {
      const core::Scene scene = withEffects(bench, effects);
      if (scene.materials.combineRule() != core::CombineRule::kMin) {
        throw std::runtime_error(bench.name + ": the reference knows the combine rule min only");
      }
      out << "scene " << referenceName(bench, effects) << " duration " << hex(bench.duration)
          << " gravity " << (scene.effects.gravity ? 1 : 0) << " " << hex(scene.gravity)
          << " threshold " << hex(scene.restitution_threshold) << " reference " << bench.reference
          << " friction " << (scene.effects.friction ? 1 : 0) << " spin "
          << (scene.effects.spin ? 1 : 0) << "\n";
      std::set<std::string> materials;
      for (const core::BodySpec& body : scene.bodies) materials.insert(body.material);
      for (const core::ObstacleSpec& obstacle : scene.obstacles)
        materials.insert(obstacle.material);
      for (const std::string& material : materials) {
        if (material == "concrete") continue;
        out << "material " << material << " "
            << hex(*scene.materials.restitution(material, "concrete")) << " "
            << hex(*scene.materials.friction(material, material)) << "\n";
      }
      for (const core::BodySpec& body : scene.bodies) {
        out << "body " << body.id << " " << body.material << " " << hex(body.mass) << " "
            << hex(body.radius) << " " << hex(body.position) << " " << hex(body.velocity) << "\n";
      }
      for (const core::ObstacleSpec& obstacle : scene.obstacles) {
        if (obstacle.shape == core::ObstacleShape::kPlane) {
          out << "plane " << obstacle.id << " " << obstacle.material << " "
              << hex(obstacle.normal.normalized()) << " " << hex(obstacle.offset) << "\n";
        } else if (obstacle.shape == core::ObstacleShape::kMesh) {  // its triangles: not needed
          out << "mesh " << obstacle.id << " " << obstacle.material << "\n";
        } else if (obstacle.shape == core::ObstacleShape::kBox) {  // along the axes
          out << "box " << obstacle.id << " " << obstacle.material << " " << hex(obstacle.position)
              << " " << hex(obstacle.size) << "\n";
        } else {
          out << "sphere " << obstacle.id << " " << obstacle.material << " "
              << hex(obstacle.position) << " " << hex(obstacle.radius) << "\n";
        }
      }
      for (std::size_t o = 0; o < bench.obstacle_velocities.size(); ++o) {
        out << "obstacle_velocity " << scene.obstacles[o].id << " "
            << hex(bench.obstacle_velocities[o]) << "\n";
      }
      out << "end\n";
    }
  }
}

References References::read(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw std::runtime_error("cannot read " + path +
                             " (python3 bench/accuracy/reference/make_references.py writes it)");
  }
  References references;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string scene, key;
    fields >> scene >> key;
    std::vector<double> row;
    std::string value;
    while (fields >> value) {
      try {
        row.push_back(std::stod(value));
      } catch (const std::exception&) {
        throw std::runtime_error(path + ":" + std::to_string(number) + ": not a number: " + value);
      }
    }
    if (key.empty()) throw std::runtime_error(path + ":" + std::to_string(number) + ": no key");
    references.data_[scene][key].push_back(row);
  }
  return references;
}

bool References::has(const std::string& scene, const std::string& key) const {
  const auto found = data_.find(scene);
  return found != data_.end() && found->second.count(key) != 0;
}

const std::vector<std::vector<double>>& References::rows(const std::string& scene,
                                                         const std::string& key) const {
  if (!has(scene, key)) {
    throw std::runtime_error("reference " + scene + " " + key +
                             " missing: regenerate bench/accuracy/reference/references.txt");
  }
  return data_.at(scene).at(key);
}

}  // namespace collision_response::bench

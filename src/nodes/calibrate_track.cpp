// calibrate_track: the core's calibration (collision_response/core/calibration.h) of one body's
// recorded states, for `rosrun collision_response calibrate` (scripts/calibrate), which reads the
// bag and calls this program so that the fit, and its reading of the scene, are the core's alone.
//
// usage: calibrate_track INPUT   (INPUT "-": standard input)
//
// INPUT has one item a line, words separated by spaces ('#' starts a comment). Either the scene:
//   scene FILE     (the scene, the `scene:` mapping of a scene file as an XML-RPC <value>, as
//                   rosparam gives it to the node: read by the node's loader and the core's
//                   sceneCalibration, the live fit's reading: its fixed planes, gravity, drag,
//                   Magnus, one obstacle pair a plane material)
//   body ID        (the scene's body whose states these are: its radius, inertia, mass, C_d, C_L)
//   fit_drag 0|1   (with the scene's drag: fit C_d)
//   fit_lift 0|1   (with the scene's magnus: fit C_L)
// or the fit's settings one by one:
//   radius R | inertia solid|hollow | gravity X Y Z
//   drag AIR_DENSITY MASS DRAG_COEFFICIENT FIT_DRAG(0|1) | plane NX NY NZ OFFSET (one a plane)
//   group I J ...   (plane indices whose bounces are summed up together: one obstacle pair)
// and with either:
//   fit_gravity 0|1 | flight_only 0|1
//   spin_before X Y Z | max_bounces N | min_bounce_speed V | max_gap_periods P
//   fitted_step DT  (also print the fitted motion's centre every DT s over the fit's span)
//   sample T X Y Z [WX WY WZ]   (one a sample, in time order; W: the tracker's spin)
// Prints the result as one JSON object on standard output; exit status 0, or 1 with
// {"error": {"problem": ..., "field": ..., "reason": ..., "message": ...}} when the recording gives
// no coefficients, or 2 with a message on standard error when INPUT cannot be read.
#include <XmlRpcValue.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "collision_response/core/calibration.h"
#include "collision_response/ros/scene_loader.h"

namespace {

using collision_response::core::Calibration;
using collision_response::core::CalibrationOptions;
using collision_response::core::Coefficients;
using collision_response::core::Estimate;
using collision_response::core::TrackedSample;

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string number(double value) {
  if (!std::isfinite(value)) return "null";
  std::ostringstream out;
  out.precision(std::numeric_limits<double>::max_digits10);
  out << value;
  return out.str();
}

std::string estimate(const Estimate& e) {
  return "{\"value\": " + number(e.value) + ", \"standard_error\": " + number(e.standard_error) +
         ", \"low\": " + number(e.low()) + ", \"high\": " + number(e.high()) + "}";
}

std::string estimates(const std::array<Estimate, 3>& e) {
  return "[" + estimate(e[0]) + ", " + estimate(e[1]) + ", " + estimate(e[2]) + "]";
}

std::string vector(const Eigen::Vector3d& v) {
  return "[" + number(v.x()) + ", " + number(v.y()) + ", " + number(v.z()) + "]";
}

std::string coefficients(const Coefficients& c) {
  std::string out = "{\"bounces\": " + std::to_string(c.bounces);
  if (c.bounces > 0) {
    out += ", \"restitution\": " + estimate(c.restitution) +
           ", \"restitution_spread\": " + number(c.restitution_spread) +
           ", \"slowest_approach\": " + number(c.slowest_approach) +
           ", \"fastest_approach\": " + number(c.fastest_approach);
    out += ", \"friction\": " + (c.friction ? estimate(*c.friction) : std::string("null"));
    out += ", \"friction_lower_bound\": " +
           (c.friction_lower_bound ? number(*c.friction_lower_bound) : std::string("null"));
  }
  return out + "}";
}

/// The names the fit's numbers belong to, with `scene` (empty without).
struct Names {
  std::string body;
  std::string body_material;
  std::vector<std::string> plane_ids;  ///< of the options' planes
  std::vector<std::string> plane_materials;
  std::vector<std::string> group_materials;  ///< of the groups: one obstacle pair a material
};

std::string strings(const std::vector<std::string>& texts) {
  std::string out = "[";
  for (std::size_t i = 0; i < texts.size(); ++i) out += (i ? ", " : "") + quoted(texts[i]);
  return out + "]";
}

std::string json(const Calibration& c, const std::vector<std::vector<std::size_t>>& groups,
                 const CalibrationOptions& options, double fitted_step, const Names& names) {
  std::ostringstream out;
  out << "{\"noise\": " << number(c.noise) << ", \"samples_used\": " << c.samples_used
      << ", \"parameters\": " << c.parameters << ", \"iterations\": " << c.iterations
      << ", \"start_time\": " << number(c.start_time) << ", \"end_time\": " << number(c.end_time)
      << ",\n \"gravity\": [" << estimate(c.gravity[0]) << ", " << estimate(c.gravity[1]) << ", "
      << estimate(c.gravity[2]) << "],\n \"drag_coefficient\": "
      << (c.drag_coefficient ? estimate(*c.drag_coefficient) : std::string("null"))
      << ",\n \"lift_coefficient\": "
      << (c.lift_coefficient ? estimate(*c.lift_coefficient) : std::string("null"))
      << ",\n \"all\": " << coefficients(c.all) << ",\n \"per_plane\": [";
  for (std::size_t i = 0; i < c.per_plane.size(); ++i) {
    out << (i ? ",\n  " : "\n  ") << coefficients(c.per_plane[i]);
  }
  out << "],\n \"body\": " << quoted(names.body)
      << ", \"body_material\": " << quoted(names.body_material)
      << ", \"radius\": " << number(options.radius)
      << ",\n \"plane_ids\": " << strings(names.plane_ids)
      << ", \"plane_materials\": " << strings(names.plane_materials)
      << ", \"group_materials\": " << strings(names.group_materials) << ",\n \"planes\": [";
  for (std::size_t i = 0; i < options.planes.size(); ++i) {
    out << (i ? ", " : "") << "{\"normal\": " << vector(options.planes[i].normal)
        << ", \"offset\": " << number(options.planes[i].offset) << "}";
  }
  out << "],\n \"groups\": [";
  for (std::size_t g = 0; g < groups.size(); ++g) {
    std::vector<std::size_t> which;
    for (std::size_t j = 0; j < c.bounces.size(); ++j) {
      for (const std::size_t plane : groups[g]) {
        if (c.bounces[j].plane == plane) which.push_back(j);
      }
    }
    out << (g ? ",\n  " : "\n  ") << coefficients(collision_response::core::combine(c, which));
  }
  out << "],\n \"fitted\": [";
  if (fitted_step > 0.0) {
    const auto steps = static_cast<long>(std::floor((c.end_time - c.start_time) / fitted_step));
    for (long k = 0; k <= steps; ++k) {
      const double t = c.start_time + static_cast<double>(k) * fitted_step;
      const Eigen::Vector3d p = collision_response::core::fittedPosition(c, options, t);
      out << (k ? ", " : "") << "[" << number(t) << ", " << number(p.x()) << ", " << number(p.y())
          << ", " << number(p.z()) << "]";
    }
  }
  out << "],\n \"bounces\": [";
  for (std::size_t j = 0; j < c.bounces.size(); ++j) {
    const auto& b = c.bounces[j];
    out << (j ? ",\n  " : "\n  ") << "{\"plane\": " << b.plane << ", \"time\": " << estimate(b.time)
        << ", \"point\": " << vector(b.point)
        << ", \"velocity_before\": " << vector(b.velocity_before)
        << ", \"velocity_after\": " << vector(b.velocity_after)
        << ", \"approach_speed\": " << estimate(b.approach_speed)
        << ", \"restitution\": " << estimate(b.restitution)
        << ", \"friction_ratio\": " << estimate(b.friction_ratio)
        << ", \"friction\": " << quoted(collision_response::core::toString(b.friction))
        << ", \"slip_after\": " << estimate(b.slip_after)
        << ", \"spin_change\": " << estimates(b.spin_change)
        << ", \"spin_after\": " << (b.spin_after ? estimates(*b.spin_after) : std::string("null"))
        << ", \"tracked_spin_after\": "
        << (b.tracked_spin_after ? estimates(*b.tracked_spin_after) : std::string("null"))
        << ", \"samples_before\": " << b.samples_before
        << ", \"samples_after\": " << b.samples_after << "}";
  }
  out << "]}";
  return out.str();
}

/// What INPUT gives.
struct Input {
  CalibrationOptions options;
  std::vector<TrackedSample> samples;
  bool flight_only = false;
  std::vector<std::vector<std::size_t>> groups;
  double fitted_step = 0.0;
  std::string scene_file;  ///< `scene`: the fit's settings from the scene
  std::string body;
  bool fit_drag = false;
  bool fit_lift = false;
  std::string one_by_one;  ///< the first setting given one by one (refused beside `scene`)
};

/// Reads INPUT; false with a message naming the line.
bool read(std::istream& in, Input& input, std::string& error) {
  CalibrationOptions& options = input.options;
  std::string line;
  int number_of_line = 0;
  while (std::getline(in, line)) {
    ++number_of_line;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;
    const auto fail = [&](const std::string& why) {
      error = "line " + std::to_string(number_of_line) + " (" + key + "): " + why;
      return false;
    };
    std::vector<double> values;
    std::string word;
    std::string text;
    while (words >> word) {
      if (key == "inertia" || key == "scene" || key == "body") {
        text = word;
        continue;
      }
      try {
        std::size_t used = 0;
        values.push_back(std::stod(word, &used));
        if (used != word.size()) return fail("not a number: '" + word + "'");
      } catch (const std::exception&) {
        return fail("not a number: '" + word + "'");
      }
    }
    const auto count = [&](std::size_t n) { return values.size() == n; };
    if (key == "radius" || key == "inertia" || key == "gravity" || key == "drag" ||
        key == "plane" || key == "group") {
      if (input.one_by_one.empty()) input.one_by_one = key;
    }
    if (key == "sample") {
      if (!count(4) && !count(7)) return fail("takes T X Y Z [WX WY WZ]");
      TrackedSample sample{values[0], Eigen::Vector3d(values[1], values[2], values[3]),
                           std::nullopt};
      if (count(7)) sample.angular_velocity = Eigen::Vector3d(values[4], values[5], values[6]);
      input.samples.push_back(sample);
    } else if (key == "scene" && !text.empty()) {
      input.scene_file = text;
    } else if (key == "body" && !text.empty()) {
      input.body = text;
    } else if (key == "fit_drag" && count(1)) {
      input.fit_drag = values[0] != 0.0;
    } else if (key == "fit_lift" && count(1)) {
      input.fit_lift = values[0] != 0.0;
    } else if (key == "radius" && count(1)) {
      options.radius = values[0];
    } else if (key == "inertia") {
      auto inertia = collision_response::core::parseInertia(text, "inertia");
      if (!inertia) return fail(inertia.error().reason);
      options.inertia = *inertia;
    } else if (key == "gravity" && count(3)) {
      options.gravity = Eigen::Vector3d(values[0], values[1], values[2]);
    } else if (key == "fit_gravity" && count(1)) {
      options.fit_gravity = values[0] != 0.0;
    } else if (key == "flight_only" && count(1)) {
      input.flight_only = values[0] != 0.0;
    } else if (key == "drag" && count(4)) {
      options.drag = true;
      options.air_density = values[0];
      options.mass = values[1];
      options.drag_coefficient = values[2];
      options.fit_drag = values[3] != 0.0;
    } else if (key == "plane" && count(4)) {
      const Eigen::Vector3d normal(values[0], values[1], values[2]);
      if (!(normal.norm() > 0.0) || !normal.allFinite()) return fail("a nonzero finite normal");
      options.planes.push_back(
          collision_response::core::Plane{normal.normalized(), values[3] / normal.norm()});
    } else if (key == "group" && !values.empty()) {
      std::vector<std::size_t> planes;
      for (const double value : values) {
        if (!(value >= 0.0) || value != std::floor(value)) return fail("plane indices");
        planes.push_back(static_cast<std::size_t>(value));
      }
      input.groups.push_back(planes);
    } else if (key == "fitted_step" && count(1) && values[0] > 0.0) {
      input.fitted_step = values[0];
    } else if (key == "spin_before" && count(3)) {
      options.spin_before = Eigen::Vector3d(values[0], values[1], values[2]);
    } else if (key == "max_bounces" && count(1) && values[0] >= 0) {
      options.max_bounces = static_cast<std::size_t>(values[0]);
    } else if (key == "min_bounce_speed" && count(1)) {
      options.min_bounce_speed = values[0];
    } else if (key == "max_gap_periods" && count(1)) {
      options.max_gap_periods = values[0];
    } else {
      return fail("unknown item, or the wrong number of values");
    }
  }
  return true;
}

/// With `scene`: the fit's settings from the scene, as the live fit reads them
/// (core::sceneCalibration, core::forBody), the fit's own (fit_gravity, spin_before, ...) kept;
/// the planes' names and one group a plane material into `names`. False with a message.
bool applyScene(Input& input, Names& names, std::string& error) {
  if (!input.one_by_one.empty()) {
    error = "`" + input.one_by_one + "` beside `scene`: the scene gives the fit's settings";
    return false;
  }
  std::ifstream file(input.scene_file);
  if (!file) {
    error = "cannot read the scene " + input.scene_file;
    return false;
  }
  const std::string xml((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  XmlRpc::XmlRpcValue value;
  int offset = 0;
  if (!value.fromXml(xml, &offset)) {
    error = input.scene_file + ": not an XML-RPC <value>";
    return false;
  }
  const auto scene = collision_response::loadScene(value, "scene");
  if (!scene) {
    error = scene.error().message();
    return false;
  }
  const auto reading = collision_response::core::sceneCalibration(*scene);
  if (!reading) {
    error = reading.error().reason;
    return false;
  }
  const collision_response::core::BodySpec* body = nullptr;
  for (const auto& spec : scene->bodies) {
    if (spec.id == input.body) body = &spec;
  }
  if (body == nullptr) {
    error = "body: '" + input.body + "' is not a body of the scene";
    return false;
  }
  CalibrationOptions options = collision_response::core::forBody(
      reading->options, collision_response::core::bodyCalibration(*body));
  if (input.fit_drag && !options.drag) {
    error = "fit_drag: the scene has no `drag` effect";
    return false;
  }
  options.fit_drag = input.fit_drag;
  if (input.fit_lift && !options.magnus) {
    error = "fit_lift: the scene has no `magnus` effect";
    return false;
  }
  options.fit_lift = input.fit_lift;
  options.fit_gravity = input.options.fit_gravity;
  options.spin_before = input.options.spin_before;
  options.max_bounces = input.options.max_bounces;
  options.min_bounce_speed = input.options.min_bounce_speed;
  options.max_gap_periods = input.options.max_gap_periods;
  input.options = options;
  names.body = body->id;
  names.body_material = body->material;
  names.plane_ids = reading->plane_ids;
  names.plane_materials = reading->plane_materials;
  // One obstacle pair a material: its planes' bounces summed up together.
  for (std::size_t i = 0; i < names.plane_materials.size(); ++i) {
    const auto known = std::find(names.group_materials.begin(), names.group_materials.end(),
                                 names.plane_materials[i]);
    if (known == names.group_materials.end()) {
      names.group_materials.push_back(names.plane_materials[i]);
      input.groups.push_back({i});
    } else {
      input.groups[static_cast<std::size_t>(known - names.group_materials.begin())].push_back(i);
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: calibrate_track INPUT   (INPUT '-': standard input)\n";
    return 2;
  }
  Input input;
  Names names;
  std::string error;
  bool good = false;
  if (std::string(argv[1]) == "-") {
    good = read(std::cin, input, error);
  } else {
    std::ifstream file(argv[1]);
    if (!file) {
      std::cerr << "calibrate_track: cannot read " << argv[1] << "\n";
      return 2;
    }
    good = read(file, input, error);
  }
  if (good && !input.scene_file.empty()) good = applyScene(input, names, error);
  if (!good) {
    std::cerr << "calibrate_track: " << error << "\n";
    return 2;
  }
  const auto result = input.flight_only
                          ? collision_response::core::fitFlight(input.samples, input.options)
                          : collision_response::core::calibrate(input.samples, input.options);
  if (!result.ok()) {
    const auto& e = result.error();
    std::cout << "{\"error\": {\"problem\": "
              << quoted(collision_response::core::toString(e.problem))
              << ", \"field\": " << quoted(e.field) << ", \"reason\": " << quoted(e.reason)
              << ", \"message\": " << quoted(e.message()) << "}}\n";
    return 1;
  }
  std::cout << json(*result, input.groups, input.options, input.fitted_step, names) << "\n";
  return 0;
}

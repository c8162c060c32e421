// What every engine's run on the real cube tosses shares (bench/cube_tosses/main.cpp for the
// peers, ours.cpp for our model; scripts/cube_tosses.sh): the tosses read from their folder and
// split into fitting and evaluation tosses, each toss's first state, the angle between two
// orientations, the grid e and mu are fitted on, and the JSON the report reads. One place, so
// that every engine is fitted on the same tosses by the same grid.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cube_tosses.h"

namespace collision_response::bench::cube_tosses {

constexpr double kPi = 3.14159265358979323846;
/// Every kFitStride-th toss (by file name) is a fitting toss.
constexpr std::size_t kFitStride = 4;
/// The coarse grid, denser in mu (the slide's length, and so the error, turns on it sharply); the
/// fine one: kFineSteps steps either side of the coarse best, of kFineRestitutionStep and
/// kFineFrictionStep.
inline const std::vector<double> kCoarseRestitutions = {0.0, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9};
inline const std::vector<double> kCoarseFrictions = {0.05, 0.1, 0.15, 0.2, 0.25,
                                                     0.3,  0.4, 0.5,  0.7, 1.0};
constexpr double kFineRestitutionStep = 0.05;
constexpr double kFineFrictionStep = 0.025;
constexpr int kFineSteps = 2;

struct Recorded {
  Pose pose;
  V velocity = V::Zero();
  V body_angular_velocity = V::Zero();  ///< rad/s, in the cube's frame, as the data give it
};

struct Toss {
  std::string name;  ///< its file's name
  std::vector<Recorded> samples;
};

/// One toss's file: a header line, then t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz (README of the
/// data set). A malformed line is an error naming the file and the line.
inline Toss readToss(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  Toss toss{file.filename().string(), {}};
  std::string line;
  std::getline(in, line);
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream words(line);
    double value[14];
    for (double& v : value) {
      if (!(words >> v) || !std::isfinite(v)) {
        throw std::runtime_error(file.string() + ":" + std::to_string(number) +
                                 ": expected 14 finite numbers (t,x,y,z,qw,qx,qy,qz,vx,vy,vz,"
                                 "wx,wy,wz)");
      }
    }
    Recorded sample;
    sample.pose.position = V(value[1], value[2], value[3]);
    const Q q(value[4], value[5], value[6], value[7]);
    if (q.norm() < 0.5) {
      throw std::runtime_error(file.string() + ":" + std::to_string(number) +
                               ": the orientation (qw,qx,qy,qz) is not a unit quaternion");
    }
    sample.pose.orientation = q.normalized();
    sample.velocity = V(value[8], value[9], value[10]);
    sample.body_angular_velocity = V(value[11], value[12], value[13]);
    toss.samples.push_back(sample);
  }
  if (toss.samples.size() < 2) throw std::runtime_error(file.string() + ": fewer than 2 samples");
  return toss;
}

/// Every toss_*.csv of `folder`, in the order of their names; none is an error.
inline std::vector<Toss> readTosses(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("toss_", 0) == 0 && entry.path().extension() == ".csv") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw std::runtime_error("no toss_*.csv in " + folder.string());
  std::vector<Toss> tosses;
  for (const auto& file : files) tosses.push_back(readToss(file));
  return tosses;
}

/// The fitting tosses (every kFitStride-th by name) and the evaluation tosses (the others).
inline void splitTosses(const std::vector<Toss>& tosses, std::vector<const Toss*>& fitting,
                        std::vector<const Toss*>& evaluation) {
  for (std::size_t i = 0; i < tosses.size(); ++i) {
    (i % kFitStride == 0 ? fitting : evaluation).push_back(&tosses[i]);
  }
}

/// The toss's first state in the world frame (the angular velocity turned out of the body's).
inline State firstState(const Toss& toss) {
  const Recorded& first = toss.samples.front();
  return State{first.pose, first.velocity, first.pose.orientation * first.body_angular_velocity};
}

/// The angle of the rotation between two orientations, in [0, 180] deg.
inline double angleBetween(const Q& a, const Q& b) {
  const Q turn = a.conjugate() * b;
  return 2.0 * std::atan2(turn.vec().norm(), std::abs(turn.w())) * 180.0 / kPi;
}

/// This process's CPU time, s.
inline double cpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

struct Fit {
  Contact best;
  double objective = std::numeric_limits<double>::infinity();
  std::size_t evaluations = 0;
  double cpu = 0.0;  ///< s
};

inline std::vector<double> fineValues(double centre, double step, double low, double high) {
  std::vector<double> values;
  for (int i = -kFineSteps; i <= kFineSteps; ++i) {
    const double value = centre + static_cast<double>(i) * step;
    if (value >= low - 1e-12 && value <= high + 1e-12) values.push_back(value);
  }
  return values;
}

/// The pair of least `objective` over the grid, coarse then fine (e held at 0 where
/// `fits_restitution` is false); `report` is told each point's objective.
inline Fit fitOnGrid(bool fits_restitution, const std::function<double(const Contact&)>& objective,
                     const std::function<void(const Contact&, double)>& report) {
  const double started = cpuSeconds();
  Fit result;
  const auto grid = [&](const std::vector<double>& restitutions,
                        const std::vector<double>& frictions) {
    for (const double e : fits_restitution ? restitutions : std::vector<double>{0.0}) {
      for (const double mu : frictions) {
        const Contact contact{e, mu};
        const double value = objective(contact);
        ++result.evaluations;
        report(contact, value);
        if (value < result.objective) {
          result.objective = value;
          result.best = contact;
        }
      }
    }
  };
  grid(kCoarseRestitutions, kCoarseFrictions);
  const Contact coarse = result.best;
  grid(fineValues(coarse.restitution, kFineRestitutionStep, 0.0, 1.0),
       fineValues(coarse.friction, kFineFrictionStep, 0.01, 1.5));
  result.cpu = cpuSeconds() - started;
  return result;
}

inline std::string json(double value) {
  if (!std::isfinite(value)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

inline std::string jsonList(const std::vector<double>& values) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + json(values[i]);
  return text + "]";
}

inline std::string jsonNames(const std::vector<const Toss*>& tosses) {
  std::string text = "[";
  for (std::size_t i = 0; i < tosses.size(); ++i) {
    text += (i ? ", \"" : "\"") + tosses[i]->name + "\"";
  }
  return text + "]";
}

/// A JSON string: `text` quoted, its quotes, backslashes and control characters escaped.
inline std::string jsonText(const std::string& text) {
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      quoted += '\\';
      quoted += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", static_cast<unsigned>(c));
      quoted += escaped;
    } else {
      quoted += c;
    }
  }
  return quoted + "\"";
}

/// The run's JSON to standard output (`path` empty) or to `path`, a file that cannot be written
/// an error naming it.
inline void writeJson(const std::string& text, const std::string& path) {
  if (path.empty()) {
    std::cout << text;
    return;
  }
  std::ofstream file(path);
  file << text;
  if (!file) throw std::runtime_error(path + ": cannot be written");
}

/// A run's main: its errors said on standard error under its `name`, exit 1.
inline int mainOf(const char* name, int (*run)(int, char**), int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& error) {
    std::cerr << name << ": " << error.what() << "\n";
    return 1;
  }
}

}  // namespace collision_response::bench::cube_tosses

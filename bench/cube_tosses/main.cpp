// The real cube tosses replayed by the peer engines (scripts/cube_tosses.sh writes
// doc/cube_tosses.md from what this prints). For each peer found at build time:
// 1. the tosses are split: every 4th one by file name (toss_000, toss_008, ...) is a fitting
//    toss, the others are evaluation tosses;
// 2. e and mu are fitted on the fitting tosses by a grid, coarse then fine (the least mean, over
//    the fitting tosses, of each toss's mean centre error in cube widths);
// 3. each evaluation toss is played from its first recorded state at the fitted e and mu, for
//    the recorded duration, sampled at 1/148 s, and measured against the recording: the centre's
//    distance in cube widths and the orientation's angle (deg), mean over the toss and at rest
//    (the last sample); the CPU per toss;
// 4. what no parameter explains: each evaluation toss's least error over the coarse grid (its
//    own best e and mu).
//   cube_tosses_peers [--tosses DIR] [--out FILE.json] [--only PEER]
// The tosses are read from DIR, else COLLISION_RESPONSE_CUBE_TOSSES (environment), else the
// folder beside the project's root; missing, the program says so and exits with 77 (skipped).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "cube_tosses.h"
#include "tosses.h"

namespace collision_response::bench::cube_tosses {
namespace {

/// A played toss against its recording.
struct Errors {
  std::vector<double> distance;  ///< the centres' distance, in cube widths, per sample
  std::vector<double> angle;     ///< the angle of the turn from one orientation to the other, deg
  double mean_distance = 0.0, rest_distance = 0.0, mean_angle = 0.0, rest_angle = 0.0;
};

Errors measure(const std::vector<Pose>& path, const Toss& toss) {
  Errors errors;
  const std::size_t n = toss.samples.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Pose& recorded = toss.samples[k].pose;
    errors.distance.push_back((path[k].position - recorded.position).norm() / kWidth);
    errors.angle.push_back(angleBetween(path[k].orientation, recorded.orientation));
    errors.mean_distance += errors.distance.back() / static_cast<double>(n);
    errors.mean_angle += errors.angle.back() / static_cast<double>(n);
  }
  errors.rest_distance = errors.distance.back();
  errors.rest_angle = errors.angle.back();
  return errors;
}

/// The fitting objective: the mean over `tosses` of each toss's mean centre error (widths).
double meanError(const Peer& peer, const Contact& contact, const std::vector<const Toss*>& tosses) {
  const Simulate simulate = peer.make(contact);
  double sum = 0.0;
  for (const Toss* toss : tosses) {
    sum += measure(simulate(firstState(*toss), toss->samples.size()), *toss).mean_distance;
  }
  return sum / static_cast<double>(tosses.size());
}

Fit fit(const Peer& peer, const std::vector<const Toss*>& tosses) {
  return fitOnGrid(
      peer.fits_restitution,
      [&](const Contact& contact) { return meanError(peer, contact, tosses); },
      [](const Contact& contact, double objective) {
        std::cerr << "   e " << contact.restitution << ", mu " << contact.friction << ": "
                  << objective << " widths\n";
      });
}

/// Each evaluation toss's errors at every sample (`series` of its Errors), so that the report
/// can take them over any span (ours.cpp's: where our prediction ends).
std::string jsonSeries(const std::vector<Errors>& errors, std::vector<double> Errors::*series) {
  std::string text = "[";
  for (std::size_t i = 0; i < errors.size(); ++i) {
    text += (i ? ",\n       " : "") + jsonList(errors[i].*series);
  }
  return text + "]";
}

/// Everything measured for one peer, as a JSON object.
std::string runPeer(const Peer& peer, const std::vector<const Toss*>& fitting,
                    const std::vector<const Toss*>& evaluation) {
  std::cerr << "== " << peer.name << ": fitting on " << fitting.size() << " tosses\n";
  const Fit fitted = fit(peer, fitting);
  std::cerr << "   e " << fitted.best.restitution << ", mu " << fitted.best.friction
            << ", mean error " << fitted.objective << " widths (" << fitted.evaluations
            << " grid points, " << fitted.cpu << " s CPU)\n";

  const Simulate simulate = peer.make(fitted.best);
  std::vector<Errors> errors;
  double played = 0.0;  // s simulated
  const double started = cpuSeconds();
  for (const Toss* toss : evaluation) {
    errors.push_back(measure(simulate(firstState(*toss), toss->samples.size()), *toss));
    played += static_cast<double>(toss->samples.size() - 1) / kSampleRate;
  }
  const double cpu = cpuSeconds() - started;

  // Each evaluation toss's own best over the coarse grid: what no parameter explains.
  const double oracle_started = cpuSeconds();
  std::vector<double> best_mean(evaluation.size(), std::numeric_limits<double>::infinity());
  std::vector<double> best_rest(evaluation.size(), std::numeric_limits<double>::infinity());
  for (const double e :
       peer.fits_restitution ? kCoarseRestitutions : std::vector<double>{fitted.best.restitution}) {
    for (const double mu : kCoarseFrictions) {
      const Simulate at = peer.make(Contact{e, mu});
      for (std::size_t i = 0; i < evaluation.size(); ++i) {
        const Toss& toss = *evaluation[i];
        const Errors own = measure(at(firstState(toss), toss.samples.size()), toss);
        best_mean[i] = std::min(best_mean[i], own.mean_distance);
        best_rest[i] = std::min(best_rest[i], own.rest_distance);
      }
    }
  }
  const double oracle_cpu = cpuSeconds() - oracle_started;
  std::cerr << "   evaluated " << evaluation.size() << " tosses in " << cpu << " s CPU; each's "
            << "own best in " << oracle_cpu << " s CPU\n";

  // The median toss (by its mean centre error): its errors over time, for the plot.
  std::vector<std::size_t> order(evaluation.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return errors[a].mean_distance < errors[b].mean_distance;
  });
  const std::size_t median = order[order.size() / 2];

  std::vector<double> column[4];
  for (const Errors& toss : errors) {
    column[0].push_back(toss.mean_distance);
    column[1].push_back(toss.rest_distance);
    column[2].push_back(toss.mean_angle);
    column[3].push_back(toss.rest_angle);
  }
  std::ostringstream out;
  out << "    {\"name\": \"" << peer.name << "\", \"setting\": \"" << peer.setting << "\",\n"
      << "     \"fits_restitution\": " << (peer.fits_restitution ? "true" : "false") << ",\n"
      << "     \"fit\": {\"restitution\": " << json(fitted.best.restitution)
      << ", \"friction\": " << json(fitted.best.friction)
      << ", \"mean_distance\": " << json(fitted.objective)
      << ", \"grid_points\": " << fitted.evaluations << ", \"cpu_s\": " << json(fitted.cpu)
      << "},\n"
      << "     \"cpu_per_toss_s\": " << json(cpu / static_cast<double>(evaluation.size()))
      << ", \"cpu_per_simulated_s\": " << json(cpu / played) << ",\n"
      << "     \"mean_distance\": " << jsonList(column[0]) << ",\n"
      << "     \"rest_distance\": " << jsonList(column[1]) << ",\n"
      << "     \"mean_angle\": " << jsonList(column[2]) << ",\n"
      << "     \"rest_angle\": " << jsonList(column[3]) << ",\n"
      << "     \"own_best_mean_distance\": " << jsonList(best_mean) << ",\n"
      << "     \"own_best_rest_distance\": " << jsonList(best_rest) << ",\n"
      << "     \"own_best_cpu_s\": " << json(oracle_cpu) << ",\n"
      << "     \"distance_series\": " << jsonSeries(errors, &Errors::distance) << ",\n"
      << "     \"angle_series\": " << jsonSeries(errors, &Errors::angle) << ",\n"
      << "     \"median_toss\": {\"name\": \"" << evaluation[median]->name
      << "\", \"distance\": " << jsonList(errors[median].distance)
      << ", \"angle\": " << jsonList(errors[median].angle) << "}}";
  return out.str();
}

std::vector<Peer> peers() {
  std::vector<Peer> found;
#ifdef COLLISION_RESPONSE_WITH_BULLET
  found.push_back(bulletPeer());
#endif
#ifdef COLLISION_RESPONSE_WITH_ODE
  found.push_back(odePeer());
#endif
#ifdef COLLISION_RESPONSE_WITH_MUJOCO
  found.push_back(mujocoPeer(true));
  found.push_back(mujocoPeer(false));
#endif
  return found;
}

int run(int argc, char** argv) {
  std::filesystem::path folder = COLLISION_RESPONSE_CUBE_TOSSES;
  if (const char* given = std::getenv("COLLISION_RESPONSE_CUBE_TOSSES")) folder = given;
  std::string out_path, only;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (i + 1 < argc && arg == "--tosses") {
      folder = argv[++i];
    } else if (i + 1 < argc && arg == "--out") {
      out_path = argv[++i];
    } else if (i + 1 < argc && arg == "--only") {
      only = argv[++i];
    } else {
      std::cerr << "usage: cube_tosses_peers [--tosses DIR] [--out FILE.json] [--only PEER]\n";
      return 2;
    }
  }
  if (!std::filesystem::is_directory(folder)) {
    std::cerr << "cube_tosses_peers: skipped: no cube tosses at " << folder
              << " (give --tosses DIR or set COLLISION_RESPONSE_CUBE_TOSSES)\n";
    return 77;
  }
  const std::vector<Toss> tosses = readTosses(folder);
  std::vector<const Toss*> fitting, evaluation;
  splitTosses(tosses, fitting, evaluation);

  std::vector<std::string> results;
  for (const Peer& peer : peers()) {
    if (!only.empty() && peer.name.rfind(only, 0) != 0) continue;
    results.push_back(runPeer(peer, fitting, evaluation));
  }
  std::ostringstream out;
  out << "{\"tosses\": " << tosses.size() << ", \"fit_stride\": " << kFitStride
      << ",\n \"step_s\": " << json(kStep) << ", \"sample_rate_hz\": " << json(kSampleRate)
      << ", \"width_m\": " << json(kWidth) << ", \"mass_kg\": " << json(kMass)
      << ", \"inertia_kg_m2\": " << json(kInertia) << ", \"table_top_m\": " << json(kTableTop)
      << ", \"gravity\": " << json(kGravity)
      << ",\n \"coarse_restitutions\": " << jsonList(kCoarseRestitutions)
      << ", \"coarse_frictions\": " << jsonList(kCoarseFrictions)
      << ", \"fine_restitution_step\": " << json(kFineRestitutionStep)
      << ", \"fine_friction_step\": " << json(kFineFrictionStep)
      << ", \"fine_steps\": " << kFineSteps << ",\n \"fitting\": " << jsonNames(fitting)
      << ",\n \"evaluation\": " << jsonNames(evaluation) << ",\n \"peers\": [\n";
  for (std::size_t i = 0; i < results.size(); ++i) out << (i ? ",\n" : "") << results[i];
  out << "\n]}\n";
  writeJson(out.str(), out_path);
  return 0;
}

}  // namespace
}  // namespace collision_response::bench::cube_tosses

int main(int argc, char** argv) {
  return collision_response::bench::cube_tosses::mainOf(
      "cube_tosses_peers", collision_response::bench::cube_tosses::run, argc, argv);
}

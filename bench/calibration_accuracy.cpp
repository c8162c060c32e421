// What a calibration's accuracy costs (issue 44, item 5): e's error from tracked bounces against
// the number of bounces, the tracker's rate and its noise, over many seeds of the closed-form
// throws of test/core/bouncing_ball.h (e 0.9, mu 0.03, a 20 mm ball thrown at 3 m/s onto a floor),
// and what it buys: the error of the next bounce's point predicted with the calibrated e against
// with a default one. Prints doc/calibration_accuracy.md's tables (markdown) on standard output.
//
// usage: calibration_accuracy [SEEDS]   (default 500 a row)
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bouncing_ball.h"
#include "collision_response/core/calibration.h"

namespace {

using collision_response::core::calibrate;
using collision_response::core::bouncing_ball::floorOptions;
using collision_response::core::bouncing_ball::kG;
using collision_response::core::bouncing_ball::Throw;
using collision_response::core::bouncing_ball::throwBall;

/// The default e a user without a calibration would take for a table-tennis ball: the seed's
/// hollow hard plastic ball on concrete.
constexpr double kDefaultE = 0.688;

struct Row {
  int fitted = 0;
  double squared_error = 0.0;  // of the common e
  double half_width = 0.0;     // its stated 95 % half width, summed
  int covered = 0;
  double prediction_error = 0.0;  // m, the next bounce's point with the calibrated e, summed
  double default_error = 0.0;     // m, with kDefaultE
};

Row measure(const Throw& base, int seeds) {
  Row row;
  for (int seed = 0; seed < seeds; ++seed) {
    Throw t = base;
    t.seed = 7000u + static_cast<unsigned>(seed);
    const auto track = throwBall(t);
    const auto fit = calibrate(track.samples, floorOptions(t));
    if (!fit.ok() || fit->bounces.size() != track.bounces.size()) continue;
    ++row.fitted;
    const double e = fit->all.restitution.value;
    row.squared_error += (e - t.e) * (e - t.e);
    row.half_width += 1.96 * fit->all.restitution.standard_error;
    row.covered += fit->all.restitution.low() <= t.e && t.e <= fit->all.restitution.high();
    // From the last bounce's state just before it (as a tracker would hand it over), the next
    // bounce's point: its flight lasts 2 e |vz| / g and carries v_t after; the velocity along
    // the floor after (the friction's share) is the truth's, so only e's error moves the point.
    const auto& last = track.bounces.back();
    const double horizontal = std::hypot(last.after.x(), last.after.y());
    const double approach = -last.before.z();
    row.prediction_error += horizontal * 2.0 * approach * std::abs(e - t.e) / kG;
    row.default_error += horizontal * 2.0 * approach * std::abs(kDefaultE - t.e) / kG;
  }
  return row;
}

void print(const std::string& label, const Row& row, int seeds) {
  const double n = row.fitted;
  std::printf("| %s | %d of %d | %.2g | %.2g | %.1f %% | %.2g | %.3g |\n", label.c_str(),
              row.fitted, seeds, std::sqrt(row.squared_error / n), row.half_width / n,
              100.0 * row.covered / n, 1e3 * row.prediction_error / n, 1e3 * row.default_error / n);
}

void header(const char* what) {
  std::printf(
      "\n| %s | fitted | e's RMS error | stated 95 %% half width (mean) | covered | "
      "next bounce's point, calibrated (mm) | with e = 0.688 (mm) |\n",
      what);
  std::printf("|---|---|---|---|---|---|---|\n");
}

}  // namespace

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 500;
  if (seeds < 1) {
    std::fprintf(stderr, "usage: calibration_accuracy [SEEDS]   (SEEDS >= 1)\n");
    return 2;
  }
  std::printf(
      "Each row: %d seeds of a throw (e 0.9, mu 0.03, a 20 mm ball at 3 m/s along the "
      "floor, no spin) tracked with Gaussian noise on each coordinate; the common e of its "
      "bounces.\n",
      seeds);
  header("bounces (200 Hz, 1 mm)");
  for (const int bounces : {1, 2, 3, 5, 8}) {
    Throw t;
    t.bounces = bounces;
    print(std::to_string(bounces), measure(t, seeds), seeds);
  }
  header("rate (5 bounces, 1 mm)");
  for (const double rate : {30.0, 60.0, 120.0, 200.0, 250.0}) {
    Throw t;
    t.rate = rate;
    print(std::to_string(static_cast<int>(rate)) + " Hz", measure(t, seeds), seeds);
  }
  header("noise (5 bounces, 200 Hz)");
  for (const double noise : {0.3e-3, 1e-3, 3e-3, 10e-3}) {
    Throw t;
    t.noise = noise;
    char label[32];
    std::snprintf(label, sizeof label, "%g mm", 1e3 * noise);
    print(label, measure(t, seeds), seeds);
  }
  return 0;
}

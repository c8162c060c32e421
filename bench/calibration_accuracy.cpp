// What a calibration's accuracy costs (issue 44, item 5): e's error from tracked bounces against
// the number of bounces, the tracker's rate and its noise, over many seeds of the closed-form
// throws of test/core/bouncing_ball.h (e 0.9, mu 0.03, a 20 mm ball thrown at 3 m/s onto a floor),
// and what it buys: the second bounce's point predicted by the monitor's own prediction
// (core::predictImpacts) from the state before the first bounce, with the calibrated e and mu
// against the seed's coefficients. Prints doc/calibration_accuracy.md's tables (markdown) on
// standard output.
//
// usage: calibration_accuracy [SEEDS]   (default 500 a row)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bouncing_ball.h"
#include "collision_response/core/calibration.h"
#include "second_bounce.h"

namespace {

using collision_response::core::calibrate;
using collision_response::core::bouncing_ball::floorOptions;
using collision_response::core::bouncing_ball::kG;
using collision_response::core::bouncing_ball::Throw;
using collision_response::core::bouncing_ball::throwBall;
using namespace collision_response::core::second_bounce;  // NOLINT: the bench's fixtures

/// What a prediction gave, or the bench stops naming why (a scene or request refused).
template <typename T>
T orExit(const collision_response::core::Expected<T>& result) {
  if (!result.ok()) {
    std::fprintf(stderr, "calibration_accuracy: %s\n", result.error().message().c_str());
    std::exit(1);
  }
  return *result;
}

/// m, the second bounce's error (second_bounce.h); NaN when the prediction finds no second.
double secondBounce(const Throw& t, const Truth& truth,
                    const collision_response::core::Scene& scene, const std::string& material) {
  return orExit(secondBounceError(t, truth, scene, material)).value_or(NAN);
}

struct Row {
  int fitted = 0;
  double squared_error = 0.0;  // of the common e
  double half_width = 0.0;     // its stated 95 % half width, summed
  int covered = 0;
  // m, the second bounce's centre predicted from before the first: its error summed with the
  // calibrated e and mu, with the seed's material, and the largest with the truth's e and mu
  // (the prediction's own error: the check that the rest is the coefficients').
  double prediction_error = 0.0;
  double default_error = 0.0;
  double truth_error = 0.0;
  int mu_bound_only = 0;          // fits whose mu was a lower bound only (taken as mu)
  double mu_squared_error = 0.0;  // of the common mu
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
    // The second bounce predicted by the monitor's model from the truth's state before the
    // first: only the coefficients differ.
    double mu = 0.0;
    if (fit->all.friction) {
      mu = fit->all.friction->value;
    } else {
      ++row.mu_bound_only;
      mu = fit->all.friction_lower_bound.value_or(0.0);
    }
    row.mu_squared_error += (mu - t.mu) * (mu - t.mu);
    const Truth truth = truthOf(t);
    const auto scene = orExit(floorScene(t, std::clamp(e, 0.0, 1.0), mu));
    const auto truth_scene = orExit(floorScene(t, t.e, t.mu));
    row.prediction_error += secondBounce(t, truth, scene, kGivenMaterial);
    row.default_error += secondBounce(t, truth, scene, kSeedMaterial);
    row.truth_error =
        std::max(row.truth_error, secondBounce(t, truth, truth_scene, kGivenMaterial));
  }
  return row;
}

void print(const std::string& label, const Row& row, int seeds) {
  const double n = row.fitted;
  std::printf("| %s | %d of %d | %.2g | %.2g | %.1f %% | %.2g | %.2g | %.3g | %.1g |\n",
              label.c_str(), row.fitted, seeds, std::sqrt(row.squared_error / n),
              row.half_width / n, 100.0 * row.covered / n, std::sqrt(row.mu_squared_error / n),
              1e3 * row.prediction_error / n, 1e3 * row.default_error / n, 1e3 * row.truth_error);
  if (row.mu_bound_only > 0) {
    std::fprintf(stderr, "%s: %d fits gave mu as a lower bound only (taken as mu)\n", label.c_str(),
                 row.mu_bound_only);
  }
}

void header(const char* what) {
  std::printf(
      "\n| %s | fitted | e's RMS error | stated 95 %% half width (mean) | covered | "
      "mu's RMS error | second bounce predicted, calibrated (mm, mean) | seed's coefficients (mm, "
      "mean) | "
      "truth's coefficients (mm, largest) |\n",
      what);
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
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

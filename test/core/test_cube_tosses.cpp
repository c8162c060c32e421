// Real tracked flights (issue 44): 285 tosses of a 10.48 cm acrylic cube onto a table, motion
// capture at 148 Hz, from the real-world data set of ContactNets (Pfrommer, Halm and Posa, CoRL
// 2020; DAIRLab/contact-nets, BSD 3-Clause), kept outside the repository and read where they are,
// never copied (doc/model.md, "Calibration"): each toss's flight before its first contact (its
// lowest corner more than 5 mm above the table's top, z = -0.001 m) fitted with gravity free
// (core/calibration.h's fitFlight: the centre of a body in free flight follows a parabola whatever
// it turns). The folder is COLLISION_RESPONSE_CUBE_TOSSES (environment) or the one beside the
// project's root; missing, the test is skipped, saying so.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "collision_response/core/calibration.h"

namespace collision_response::core {
namespace {

constexpr double kHalfWidth = 0.0524;  // m, the data set's half width of the cube
constexpr double kTableTop = -0.001;   // m, the table's top in the data set's frame
constexpr double kClearance = 0.005;   // m: a flight's samples are this far above the table

std::filesystem::path tossFolder() {
  if (const char* folder = std::getenv("COLLISION_RESPONSE_CUBE_TOSSES")) return folder;
  return COLLISION_RESPONSE_CUBE_TOSSES;
}

/// The toss's samples before its lowest corner first comes within kClearance of the table.
std::vector<TrackedSample> flightBeforeContact(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz
  std::vector<TrackedSample> flight;
  while (std::getline(in, line)) {
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream words(line);
    double t, x, y, z, qw, qx, qy, qz;
    if (!(words >> t >> x >> y >> z >> qw >> qx >> qy >> qz)) break;
    const Eigen::Matrix3d turn = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    // The lowest corner: each of the body's axes turned down by its half width.
    const double lowest = z - kHalfWidth * turn.row(2).cwiseAbs().sum();
    if (lowest < kTableTop + kClearance) break;
    flight.push_back(TrackedSample{t, Eigen::Vector3d(x, y, z), std::nullopt});
  }
  return flight;
}

TEST(CubeTosses, FlightPhasesGiveGravityAndTheTrackersNoise) {
  const auto folder = tossFolder();
  if (!std::filesystem::is_directory(folder)) {
    GTEST_SKIP() << "no cube tosses at " << folder
                 << " (set COLLISION_RESPONSE_CUBE_TOSSES to their folder)";
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const auto name = entry.path().filename().string();
    if (name.rfind("toss_", 0) == 0 && entry.path().extension() == ".csv") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty()) << folder;

  CalibrationOptions options;
  options.fit_gravity = true;
  std::vector<double> down;
  std::vector<double> across;
  std::vector<double> noise;
  std::vector<Estimate> each;
  for (const auto& file : files) {
    const auto flight = flightBeforeContact(file);
    const auto fit = fitFlight(flight, options);
    if (!fit.ok()) {
      // A flight too short to fit (fewer than 8 samples above the table) is named, not a crash.
      EXPECT_EQ(fit.error().problem, RecordingProblem::kTooFewSamples) << fit.error().message();
      continue;
    }
    down.push_back(-fit->gravity[2].value);
    across.push_back(std::hypot(fit->gravity[0].value, fit->gravity[1].value));
    noise.push_back(fit->noise);
    each.push_back(fit->gravity[2]);
  }
  ASSERT_GE(down.size(), files.size() * 9 / 10) << "most flights fit";
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  double mean = 0.0;
  for (const double g : down) mean += g;
  mean /= static_cast<double>(down.size());
  double spread = 0.0;
  for (const double g : down) spread += (g - mean) * (g - mean);
  spread = std::sqrt(spread / static_cast<double>(down.size() - 1));
  int covering = 0;
  for (const auto& g : each) covering += g.low() <= -mean && -mean <= g.high();
  std::printf(
      "cube tosses: %zu of %zu flights fitted; g down %.3f m/s^2 (mean; spread %.3f over tosses, "
      "median %.3f), across %.3f (median); the fit's residual %.4f mm (median); each toss's 95 %% "
      "interval of g_z covers the mean in %d of %zu\n",
      down.size(), files.size(), mean, spread, median(down), median(across), 1e3 * median(noise),
      covering, each.size());
  // Gravity (9.81 m/s^2) to within 3 %, and about vertical: the flights are free flights. The
  // data give 9.607, 2 % low, with the README's 148 Hz taken as exact (146.5 Hz would give 9.81;
  // measured, not explained), and 0.17 m/s^2 across (median, in directions that vary by toss).
  EXPECT_NEAR(mean, 9.81, 0.03 * 9.81);
  EXPECT_LT(median(across), 0.05 * 9.81);
  // The rows are processed odometry: the residual (about 0.02 mm) is far below a motion capture's
  // noise, and successive residuals are not independent, so each toss's interval, which assumes
  // independent noise, is too narrow (it covers the tosses' mean in a minority of them): said in
  // the printout, not held.
  EXPECT_LT(median(noise), 1e-3);
}

}  // namespace
}  // namespace collision_response::core

// e and mu from tracked bounces (issue 44): synthetic tracks of a ball bouncing on a floor with
// known e, mu and g, flown in closed form here (parabolas; each bounce instant the root of the
// flight's quadratic; Coulomb friction with sticking as friction.h states it, derived below),
// sampled at a tracker's rate with Gaussian noise, and the fit's estimates held to the truth
// within the 95 % intervals it states.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "bouncing_ball.h"
#include "collision_response/core/calibration.h"
#include "second_bounce.h"

namespace collision_response::core {
namespace {

using namespace bouncing_ball;  // NOLINT: the test's own fixtures
using V = Eigen::Vector3d;

bool covers(const Estimate& estimate, double truth) {
  return estimate.low() <= truth && truth <= estimate.high();
}

/// Within 4 standard errors: what one track's many quantities are held to (each misses by chance
/// 6e-5 of the time, 25 of them 0.2 %), where the 95 % interval would miss one of 25 most of the
/// time; the 95 % intervals themselves are held to their coverage over 1,000 seeds below.
bool within4(const Estimate& estimate, double truth) {
  return std::abs(estimate.value - truth) <= 4.0 * estimate.standard_error;
}

void expectRecovered(const Throw& t, const Track& track, const Calibration& fit) {
  ASSERT_EQ(fit.bounces.size(), track.bounces.size());
  for (std::size_t j = 0; j < fit.bounces.size(); ++j) {
    const auto& bounce = fit.bounces[j];
    const auto& truth = track.bounces[j];
    SCOPED_TRACE("bounce " + std::to_string(j + 1));
    EXPECT_TRUE(within4(bounce.restitution, t.e))
        << bounce.restitution.value << " +- " << bounce.restitution.standard_error;
    EXPECT_TRUE(within4(bounce.time, truth.time))
        << bounce.time.value << " +- " << bounce.time.standard_error << " vs " << truth.time;
    EXPECT_TRUE(within4(bounce.approach_speed, -truth.before.z()));
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(bounce.velocity_before[i], truth.before[i], 0.05);
      EXPECT_NEAR(bounce.velocity_after[i], truth.after[i], 0.05);
    }
    const V change = truth.after - truth.before;
    const double ratio = std::hypot(change.x(), change.y()) / change.z();
    EXPECT_TRUE(within4(bounce.friction_ratio, ratio))
        << bounce.friction_ratio.value << " +- " << bounce.friction_ratio.standard_error << " vs "
        << ratio;
  }
  EXPECT_TRUE(within4(fit.all.restitution, t.e))
      << fit.all.restitution.value << " +- " << fit.all.restitution.standard_error;
}

// What a calibration buys (issue 44, item 5): the monitor's own prediction (predictImpacts) from
// the state 50 ms before the first bounce puts the second bounce where the truth has it, with the
// truth's e and mu to 1e-12 m (its impact law is the throw's); with the calibrated ones within
// their propagated error: the second bounce lies T v_t' along the slip from the first, T = 2 e
// |v_n| / g and v_t' = |v_t| - mu (1 + e) |v_n|, so it moves by (2 |v_n| / g) v_t' de + T (1 + e)
// |v_n| dmu, held to 4 standard errors of each (the two added: an upper bound); and with the seed's
// coefficients (e 0.688, mu 0.5) at the closed form's point: mu (1 + e) |v_n| > |v_t| / 3.5, the
// slip stops and the ball leaves rolling at 5/7 |v_t| (a solid ball), T = 2 (0.688) |v_n| / g.
TEST(Calibration, TheCalibratedCoefficientsPredictTheSecondBounce) {
  using namespace second_bounce;  // NOLINT: the test's own fixtures
  Throw t;
  t.seed = 44;
  const Track track = throwBall(t);
  const auto fit = calibrate(track.samples, floorOptions(t));
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  ASSERT_TRUE(fit->all.friction.has_value());
  const Estimate e = fit->all.restitution;
  const Estimate mu = *fit->all.friction;
  const Truth truth = truthOf(t);

  const double approach = -track.bounces[0].before.z();
  const double slip = std::hypot(track.bounces[0].before.x(), track.bounces[0].before.y());
  const double flight = 2.0 * t.e * approach / kG;
  const double slip_after = slip - t.mu * (1.0 + t.e) * approach;
  const double bound = 4.0 * (2.0 * approach / kG * slip_after * e.standard_error +
                              flight * (1.0 + t.e) * approach * mu.standard_error);

  const auto calibrated = floorScene(t, e.value, mu.value);
  ASSERT_TRUE(calibrated.ok()) << calibrated.error().message();
  const auto with_calibration = secondBounceError(t, truth, *calibrated, kGivenMaterial);
  ASSERT_TRUE(with_calibration.ok()) << with_calibration.error().message();
  ASSERT_TRUE(with_calibration->has_value());
  EXPECT_LE(**with_calibration, bound) << "e " << e.value << ", mu " << mu.value;

  const auto exact = floorScene(t, t.e, t.mu);
  ASSERT_TRUE(exact.ok());
  const auto with_truth = secondBounceError(t, truth, *exact, kGivenMaterial);
  ASSERT_TRUE(with_truth.ok() && with_truth->has_value());
  EXPECT_LT(**with_truth, 1e-12);

  ASSERT_GT(0.5 * (1.0 + 0.688) * approach, slip / 3.5);  // the seed's: the slip stops
  const double seed_miss =
      std::abs(2.0 * 0.688 * approach / kG * (5.0 / 7.0) * slip - flight * slip_after);
  const auto with_seed = secondBounceError(t, truth, *calibrated, kSeedMaterial);
  ASSERT_TRUE(with_seed.ok() && with_seed->has_value());
  EXPECT_NEAR(**with_seed, seed_miss, 1e-9);
  EXPECT_GT(**with_seed, 1000.0 * bound);
}

// The bar: 5 bounces at 200 Hz with 1 mm of noise give e within +-0.005 (the ITTF's
// legal ball, e from 0.887 to 0.923, told from an illegal one), every bounce sliding (mu = 0.03
// against a slip of 3 m/s: it takes 3.5 mu (1 + e) |vz| = 0.2 |vz| < 0.6 m/s of the slip a bounce).
TEST(Calibration, FiveBouncesAt200HzGiveEWithinFiveThousandths) {
  Throw t;
  const Track track = throwBall(t);
  const auto fit = calibrate(track.samples, floorOptions(t));
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  expectRecovered(t, track, *fit);
  EXPECT_NEAR(fit->all.restitution.value, t.e, 0.005);
  EXPECT_LT(1.96 * fit->all.restitution.standard_error, 0.005);
  for (const auto& bounce : fit->bounces) {
    EXPECT_EQ(bounce.friction, FrictionReading::kSliding) << toString(bounce.friction);
    EXPECT_FALSE(track.bounces[&bounce - &fit->bounces[0]].stuck);
  }
  ASSERT_TRUE(fit->all.friction.has_value());
  EXPECT_TRUE(within4(*fit->all.friction, t.mu)) << fit->all.friction->value;
  EXPECT_NEAR(fit->noise, t.noise, 0.1 * t.noise);
}

TEST(Calibration, ThreeMillimetresAt60HzRecoveredWithinTheIntervals) {
  Throw t;
  t.rate = 60.0;
  t.noise = 3e-3;
  t.seed = 7;
  const Track track = throwBall(t);
  const auto fit = calibrate(track.samples, floorOptions(t));
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  expectRecovered(t, track, *fit);
  ASSERT_TRUE(fit->all.friction.has_value());
  EXPECT_TRUE(within4(*fit->all.friction, t.mu)) << fit->all.friction->value;
}

TEST(Calibration, DroppedSamplesRecoveredWithinTheIntervals) {
  Throw t;
  t.drop = 0.1;
  t.seed = 3;
  const Track track = throwBall(t);
  Throw whole = t;
  whole.drop = 0.0;
  ASSERT_LT(static_cast<double>(track.samples.size()),
            0.95 * static_cast<double>(throwBall(whole).samples.size()));
  const auto fit = calibrate(track.samples, floorOptions(t));
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  expectRecovered(t, track, *fit);
}

// Stamps of a ROS clock (1.7e9 s, resolved to 2e-7 s) fit as stamps from 0 do: the fit counts
// time from the first sample. The fitted motion replays the track (fittedPosition) at its stamps.
TEST(Calibration, StampsOfARosClockFitAsStampsFromZero) {
  Throw t;
  t.rate = 250.0;  // periods of 4 ms: exact in binary, so the shifted stamps are the same instants
  const Track track = throwBall(t);
  const double epoch = 1.7e9;
  std::vector<TrackedSample> shifted = track.samples;
  for (auto& sample : shifted) sample.time += epoch;
  const CalibrationOptions options = floorOptions(t);
  const auto fit = calibrate(track.samples, options);
  const auto late = calibrate(shifted, options);
  ASSERT_TRUE(fit.ok() && late.ok());
  ASSERT_EQ(fit->bounces.size(), late->bounces.size());
  EXPECT_NEAR(late->all.restitution.value, fit->all.restitution.value, 1e-9);
  for (std::size_t j = 0; j < fit->bounces.size(); ++j) {
    EXPECT_NEAR(late->bounces[j].time.value - epoch, fit->bounces[j].time.value, 1e-6);
  }
  for (const auto& sample : shifted) {
    EXPECT_LT((fittedPosition(*late, options, sample.time) - sample.position).norm(), 5 * t.noise);
  }
}

// The 95 % interval of e from 5 bounces at 200 Hz with 1 mm of noise covers the truth in 93 to
// 97 % of the seeds (issue 44). 1,000 seeds (3 ms each): the fraction's binomial standard
// deviation is sqrt(0.95 * 0.05 / 1000) = 0.0069, so 93..97 % is the truth's +-2.9 standard
// deviations (a correct interval fails this test 0.4 % of the time; the seeds are fixed, so the
// test is deterministic). Both the common e and the first bounce's alone.
/// Over 1,000 seeds of `base`: how often the 95 % intervals of the common e, the first bounce's
/// e, the common mu, the first bounce's instant and its spin change (about y: the bigger part,
/// the slip being mostly along x) cover the truth, each held to 93..97 % of the
/// tracks fitted; a track refused must be refused for a gap across a bounce (three samples or
/// more dropped in a row there), at most 3 % of them.
void expectCoverage(const Throw& base, const char* what) {
  constexpr int kSeeds = 1000;
  int common = 0;
  int first = 0;
  int friction = 0;
  int instant = 0;
  int spin = 0;
  int fitted = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    Throw t = base;
    t.seed = 1000u + static_cast<unsigned>(seed);
    const Track track = throwBall(t);
    const auto fit = calibrate(track.samples, floorOptions(t));
    if (!fit.ok()) {
      EXPECT_EQ(fit.error().problem, RecordingProblem::kGapAcrossBounce) << fit.error().message();
      continue;
    }
    EXPECT_EQ(fit->bounces.size(), 5u);
    if (fit->bounces.size() != 5 || !fit->all.friction) continue;
    ++fitted;
    common += covers(fit->all.restitution, t.e);
    first += covers(fit->bounces[0].restitution, t.e);
    friction += covers(*fit->all.friction, t.mu);
    instant += covers(fit->bounces[0].time, track.bounces[0].time);
    const auto& truth = track.bounces[0];
    spin += covers(fit->bounces[0].spin_change[1], truth.spin_after.y() - truth.spin_before.y());
  }
  EXPECT_GE(fitted, kSeeds * 97 / 100);
  for (const int count : {common, first, friction, instant, spin}) {
    EXPECT_GE(count, 0.93 * fitted);
    EXPECT_LE(count, 0.97 * fitted);
  }
  std::printf(
      "%s: 95 %% intervals covering the truth in %d seeds (%d fitted): e %d, the first bounce's e "
      "%d, mu %d, the first bounce's instant %d, the first bounce's spin change (y) %d\n",
      what, kSeeds, fitted, common, first, friction, instant, spin);
}

TEST(Calibration, NinetyFivePercentIntervalsCoverTheTruthInNinetyThreeToNinetySevenPercent) {
  expectCoverage(Throw{}, "200 Hz, 1 mm");
}

// The same at 60 Hz with 3 mm of noise and a tenth of the samples dropped (a camera's track): 15
// of the 1,000 tracks have three samples or more missing in a row at a bounce, refused.
TEST(Calibration, NinetyFivePercentIntervalsCoverTheTruthAt60HzWithDroppedSamples) {
  Throw t;
  t.rate = 60.0;
  t.noise = 3e-3;
  t.drop = 0.1;
  expectCoverage(t, "60 Hz, 3 mm, 10 % dropped");
}

// Two obstacle pairs in one recording: a ball (r = 0.02 m, no friction) thrown at a wall (x = 1,
// its normal -x, e = 0.6) above a floor (z = 0, e = 0.9). Flown here: each flight a parabola up to
// the earlier of the floor's root (as throwBall) and the wall's, s = (1 - r - x) / vx (linear:
// gravity is along the wall). Each bounce is put on its plane and each plane's e recovered.
TEST(Calibration, AWallAndAFloorGiveEachTheirOwnE) {
  const double r = 0.02, e_floor = 0.9, e_wall = 0.6, rate = 200.0;
  V p(0.0, 0.0, 0.4);
  V v(2.0, 0.0, 0.5);
  double start = 0.0;
  std::vector<std::pair<double, std::pair<V, V>>> pieces;
  std::vector<std::size_t> truth_planes;  // 0 floor, 1 wall
  for (int j = 0; j < 5; ++j) {
    pieces.push_back({start, {p, v}});
    const double floor_s = (v.z() + std::sqrt(v.z() * v.z() + 2.0 * kG * (p.z() - r))) / kG;
    const double wall_s = v.x() > 0 ? (1.0 - r - p.x()) / v.x() : 1e9;
    const double s = std::min(floor_s, wall_s);
    p += s * v;
    p.z() -= 0.5 * kG * s * s;
    v.z() -= kG * s;
    if (wall_s < floor_s) {
      p.x() = 1.0 - r;
      v.x() = -e_wall * v.x();
      truth_planes.push_back(1);
    } else {
      p.z() = r;
      v.z() = -e_floor * v.z();
      truth_planes.push_back(0);
    }
    start += s;
  }
  pieces.push_back({start, {p, v}});
  std::mt19937_64 random(11);
  std::normal_distribution<double> noise(0.0, 1e-3);
  std::vector<TrackedSample> samples;
  const double end = start + 1.1 * v.z() / kG;
  for (int k = 0; k / rate <= end; ++k) {
    const double time = k / rate;
    std::size_t piece = 0;
    while (piece + 1 < pieces.size() && time >= pieces[piece + 1].first) ++piece;
    const double s = time - pieces[piece].first;
    V at = pieces[piece].second.first + s * pieces[piece].second.second;
    at.z() -= 0.5 * kG * s * s;
    samples.push_back({time, at + V(noise(random), noise(random), noise(random)), std::nullopt});
  }
  ASSERT_EQ(std::count(truth_planes.begin(), truth_planes.end(), 1u), 1);  // one wall bounce
  CalibrationOptions options;
  options.planes = {Plane{V(0, 0, 1), 0.0}, Plane{V(-1, 0, 0), -1.0}};
  options.radius = r;
  options.spin_before = V::Zero();
  const auto fit = calibrate(samples, options);
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  ASSERT_EQ(fit->bounces.size(), truth_planes.size());
  for (std::size_t j = 0; j < truth_planes.size(); ++j) {
    EXPECT_EQ(fit->bounces[j].plane, truth_planes[j]) << "bounce " << j + 1;
  }
  ASSERT_EQ(fit->per_plane.size(), 2u);
  EXPECT_EQ(fit->per_plane[0].bounces, 4u);
  EXPECT_EQ(fit->per_plane[1].bounces, 1u);
  EXPECT_TRUE(within4(fit->per_plane[0].restitution, e_floor))
      << fit->per_plane[0].restitution.value;
  EXPECT_TRUE(within4(fit->per_plane[1].restitution, e_wall))
      << fit->per_plane[1].restitution.value;
  EXPECT_EQ(fit->per_plane[1].restitution_spread, 0.0);  // one bounce: no spread
  // Without friction the floor's bounces leave v_t as it was: no slip is stopped, the ratio is 0.
  for (const auto& bounce : fit->bounces) EXPECT_TRUE(within4(bounce.friction_ratio, 0.0));
}

// Noisy tracks at 200 Hz: every bounce found and the track fitted, over 50 seeds each. At 3 mm the
// noise at a flight's top reversed the 20 ms lines' slopes and was taken for a bounce (327 of 500
// tracks fitted, calibration_accuracy); at 10 mm the last flight was cut at its first noisy sample
// below half the "top" reached so far, just after the bounce (383 of 500). Now a bounce is near
// the plane, and a top is well above the noise: 500 and 482 of 500.
TEST(Calibration, NoisyTracksAt200HzFindEveryBounce) {
  for (const double noise : {3e-3, 10e-3}) {
    int fitted = 0;
    for (unsigned seed = 0; seed < 50; ++seed) {
      Throw t;
      t.noise = noise;
      t.seed = 2000u + seed;
      const Track track = throwBall(t);
      const auto fit = calibrate(track.samples, floorOptions(t));
      fitted += fit.ok() && fit->bounces.size() == track.bounces.size();
    }
    EXPECT_GE(fitted, noise < 5e-3 ? 50 : 45) << noise << " m of noise";
  }
}

// A stuck bounce among sliding ones: thrown 8 times, the ball's slip falls by 3.5 mu (1 + e) |v_n|
// a bounce until the 7th stops it (slip before 0.024 m/s, after 0; the 8th has none). A stuck
// bounce read as sliding gives a wrong mu (its ratio, 0.002, joins the sliding bounces' 0.03 in
// their mean), where a sliding one read as stuck only gives a weaker, true, bound: the reading
// "sliding" is held to the slip after lying 4 standard errors above 0, not 1.96 (it read the 7th
// as sliding in 22 of 500 seeds, and the common mu then fell to 0.0293; its interval covered 0.03
// in 461 of 500). Over 300 seeds: no stuck bounce read as sliding, and the common mu's 95 %
// interval covers 0.03 in 93 to 97 % of them.
TEST(Calibration, AStuckBounceIsNotReadAsSliding) {
  constexpr int kSeeds = 300;
  int misread = 0;
  int covered = 0;
  int fitted = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    Throw t;
    t.bounces = 8;
    t.seed = 7000u + static_cast<unsigned>(seed);
    const Track track = throwBall(t);
    ASSERT_TRUE(track.bounces[6].stuck && track.bounces[7].stuck);
    ASSERT_FALSE(track.bounces[5].stuck);
    const auto fit = calibrate(track.samples, floorOptions(t));
    if (!fit.ok() || fit->bounces.size() != track.bounces.size()) continue;
    ++fitted;
    for (std::size_t j = 0; j < track.bounces.size(); ++j) {
      misread += track.bounces[j].stuck && fit->bounces[j].friction == FrictionReading::kSliding;
    }
    covered += fit->all.friction && covers(*fit->all.friction, t.mu);
  }
  std::printf("%d of %d fitted, stuck bounces read as sliding %d, mu covered %d\n", fitted, kSeeds,
              misread, covered);
  EXPECT_EQ(fitted, kSeeds);
  EXPECT_EQ(misread, 0);
  EXPECT_GE(covered, 0.93 * fitted);
  EXPECT_LE(covered, 0.98 * fitted);
}

// A ball dropped without spin, moving 1 m/s along the floor, on a floor of mu = 0.5: the slip
// stops within the first bounce (J_stick = m |u| / 3.5 = 0.29 m N s per kg against mu J_n =
// 0.5 (1 + e) |vz| m), so v_t after = 5/7 of before and the ratio 2/7 / ((1 + e) |vz|) is only a
// lower bound of mu: the fit says so, gives no mu, and its bound is below the truth.
TEST(Calibration, AStickingBounceGivesALowerBoundOnly) {
  Throw t;
  t.mu = 0.5;
  t.velocity = V(1.0, 0.0, -1.0);
  t.bounces = 3;
  const Track track = throwBall(t);
  ASSERT_TRUE(track.bounces[0].stuck);
  const auto fit = calibrate(track.samples, floorOptions(t));
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  expectRecovered(t, track, *fit);
  for (const auto& bounce : fit->bounces) {
    EXPECT_NE(bounce.friction, FrictionReading::kSliding) << toString(bounce.friction);
  }
  EXPECT_EQ(fit->bounces[0].friction, FrictionReading::kStoppedSlipping);
  EXPECT_FALSE(fit->all.friction.has_value());
  ASSERT_TRUE(fit->all.friction_lower_bound.has_value());
  EXPECT_LT(*fit->all.friction_lower_bound, t.mu);
  EXPECT_GT(*fit->all.friction_lower_bound, 0.0);
}

// Without the spin before the first bounce (no tracked spin, no spin_before) whether the contact
// slid cannot be told: the sliding throw of the first test gives a lower bound only.
TEST(Calibration, AnUnknownSpinGivesALowerBoundOnly) {
  Throw t;
  const Track track = throwBall(t);
  CalibrationOptions options = floorOptions(t);
  options.spin_before.reset();
  const auto fit = calibrate(track.samples, options);
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  for (const auto& bounce : fit->bounces) {
    EXPECT_EQ(bounce.friction, FrictionReading::kSpinUnknown);
  }
  EXPECT_FALSE(fit->all.friction.has_value());
  ASSERT_TRUE(fit->all.friction_lower_bound.has_value());
  EXPECT_LT(*fit->all.friction_lower_bound, t.mu);
  // The tracker's spin, when the samples carry it, is used instead: zero before the first bounce.
  std::vector<TrackedSample> spun = track.samples;
  for (auto& sample : spun) {
    if (sample.time < track.bounces[0].time) sample.angular_velocity = V::Zero();
  }
  const auto tracked = calibrate(spun, options);
  ASSERT_TRUE(tracked.ok()) << tracked.error().message();
  EXPECT_EQ(tracked->bounces[0].friction, FrictionReading::kSliding);
}

// A ball dropped straight down, tracked without noise (as the scene player plays it): e to 1e-9,
// and no slip before any bounce, so nothing about mu (the rounding's slip of 1e-17 m/s was read
// as a slip that stopped, and gave "mu >= 0").
TEST(Calibration, ADropWithoutNoiseGivesENoSlipAndNothingAboutMu) {
  Throw t;
  t.position = V(0.3, 0.0, 1.0335);  // the drop test's tennis ball: its x rounds in the fit
  t.velocity = V(0.0, 0.0, 0.0);
  t.noise = 0.0;
  t.bounces = 3;
  const Track track = throwBall(t);
  const auto fit = calibrate(track.samples, floorOptions(t));
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  ASSERT_EQ(fit->bounces.size(), 3u);
  EXPECT_NEAR(fit->all.restitution.value, t.e, 1e-9);
  for (const auto& bounce : fit->bounces) {
    EXPECT_EQ(bounce.friction, FrictionReading::kNoSlip) << toString(bounce.friction);
  }
  EXPECT_FALSE(fit->all.friction.has_value());
  EXPECT_FALSE(fit->all.friction_lower_bound.has_value());
}

/// Each bounce's spin change (and, where `spin_known`, its spin after) within 4 standard errors
/// of the closed form's (throwBall: -(5/2) / r n x dv_t, each component).
void expectSpinRecovered(const Track& track, const Calibration& fit, bool spin_known) {
  ASSERT_EQ(fit.bounces.size(), track.bounces.size());
  for (std::size_t j = 0; j < fit.bounces.size(); ++j) {
    SCOPED_TRACE("bounce " + std::to_string(j + 1));
    const auto& bounce = fit.bounces[j];
    const auto& truth = track.bounces[j];
    const V change = truth.spin_after - truth.spin_before;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto at = static_cast<Eigen::Index>(i);
      EXPECT_TRUE(within4(bounce.spin_change[i], change[at]))
          << "dw[" << i << "] " << bounce.spin_change[i].value << " +- "
          << bounce.spin_change[i].standard_error << " vs " << change[at];
    }
    ASSERT_EQ(bounce.spin_after.has_value(), spin_known);
    if (!spin_known) continue;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto at = static_cast<Eigen::Index>(i);
      EXPECT_TRUE(within4((*bounce.spin_after)[i], truth.spin_after[at]))
          << "w[" << i << "] " << (*bounce.spin_after)[i].value << " +- "
          << (*bounce.spin_after)[i].standard_error << " vs " << truth.spin_after[at];
    }
  }
}

// The spin change at a bounce (issue 44): the turn its tangential impulse gives a ball, dw =
// (r x J_t) / I = -(5/2) / r n x dv_t for a solid one, with its interval, on the closed-form
// tracks of throwBall (200 Hz, 1 mm) of a ball thrown spinning (w = (4, -15, 2) rad/s: a slip of
// 3.3 m/s along x, every bounce sliding, about 30 rad/s of turn a bounce) and of one whose first
// bounce stops slipping (mu 0.5, 1 m/s along the floor, no spin: it leaves rolling, w_y = v_x / r).
// The spin after each bounce given the spin before; without it only the change.
TEST(Calibration, TheSpinChangeAtABounceIsTheTangentialImpulsesTurn) {
  Throw spinning;
  spinning.spin = V(4.0, -15.0, 2.0);
  spinning.seed = 9;
  const Track track = throwBall(spinning);
  const auto fit = calibrate(track.samples, floorOptions(spinning));
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  expectSpinRecovered(track, *fit, true);
  for (const auto& bounce : fit->bounces) EXPECT_EQ(bounce.friction, FrictionReading::kSliding);
  // About 30 rad/s a bounce, known to a few tenths.
  EXPECT_GT(std::abs(fit->bounces[0].spin_change[1].value), 10.0);
  EXPECT_LT(fit->bounces[0].spin_change[1].standard_error, 1.0);

  CalibrationOptions unknown = floorOptions(spinning);
  unknown.spin_before.reset();
  const auto without = calibrate(track.samples, unknown);
  ASSERT_TRUE(without.ok()) << without.error().message();
  expectSpinRecovered(track, *without, false);

  Throw sticking;
  sticking.mu = 0.5;
  sticking.velocity = V(1.0, 0.0, -1.0);
  sticking.bounces = 3;
  const Track stuck = throwBall(sticking);
  ASSERT_TRUE(stuck.bounces[0].stuck);
  const auto rolled = calibrate(stuck.samples, floorOptions(sticking));
  ASSERT_TRUE(rolled.ok()) << rolled.error().message();
  expectSpinRecovered(stuck, *rolled, true);
  // Rolling after: the contact point at rest, w_y = v_x / r.
  EXPECT_NEAR(stuck.bounces[0].spin_after.y(), stuck.bounces[0].after.x() / sticking.radius, 1e-12);
}

// The tracker's spin over the flight before the first bounce alone is carried through the later
// bounces by their turns, as a spin_before is: their spin after is known and they read as sliding
// (they read "spin unknown" before, though their slip was computed from the carried spin).
TEST(Calibration, ATrackedSpinIsCarriedThroughTheLaterBounces) {
  Throw t;
  t.spin = V(4.0, -15.0, 2.0);
  t.seed = 10;
  const Track track = throwBall(t);
  std::vector<TrackedSample> spun = track.samples;
  for (auto& sample : spun) {
    if (sample.time < track.bounces[0].time) sample.angular_velocity = t.spin;
  }
  CalibrationOptions options = floorOptions(t);
  options.spin_before.reset();
  const auto fit = calibrate(spun, options);
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  expectSpinRecovered(track, *fit, true);
  for (const auto& bounce : fit->bounces) {
    EXPECT_EQ(bounce.friction, FrictionReading::kSliding) << toString(bounce.friction);
  }
  ASSERT_TRUE(fit->all.friction.has_value());
  EXPECT_TRUE(within4(*fit->all.friction, t.mu)) << fit->all.friction->value;
}

// A tracker that measures the spin (each sample the closed form's spin of its flight and 0.5 rad/s
// of Gaussian noise a component, 200 Hz): each bounce's tracked spin after (the flight's mean, its
// standard error the scatter over sqrt(n)) within 4 standard errors of the truth, beside the
// spin after the tangential impulse implies (from the tracked spin before); without tracked spin,
// none.
TEST(Calibration, ATrackersSpinAfterABounceStandsBesideTheImpliedOne) {
  Throw t;
  t.spin = V(4.0, -15.0, 2.0);
  t.seed = 12;
  const Track track = throwBall(t);
  std::mt19937_64 random(12);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::vector<TrackedSample> spun = track.samples;
  for (auto& sample : spun) {
    V spin = t.spin;
    for (const auto& bounce : track.bounces) {
      if (sample.time >= bounce.time) spin = bounce.spin_after;
    }
    sample.angular_velocity = spin + V(noise(random), noise(random), noise(random));
  }
  CalibrationOptions options = floorOptions(t);
  options.spin_before.reset();
  const auto fit = calibrate(spun, options);
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  expectSpinRecovered(track, *fit, true);
  for (std::size_t j = 0; j < fit->bounces.size(); ++j) {
    SCOPED_TRACE("bounce " + std::to_string(j + 1));
    const auto& tracked = fit->bounces[j].tracked_spin_after;
    ASSERT_TRUE(tracked.has_value());
    for (std::size_t i = 0; i < 3; ++i) {
      const double truth = track.bounces[j].spin_after[static_cast<Eigen::Index>(i)];
      EXPECT_TRUE(within4((*tracked)[i], truth))
          << (*tracked)[i].value << " +- " << (*tracked)[i].standard_error << " vs " << truth;
      // About 0.5 / sqrt(n) for the flight's n samples (tens of them).
      EXPECT_LT((*tracked)[i].standard_error, 0.2);
    }
  }
  const auto untracked = calibrate(track.samples, floorOptions(t));
  ASSERT_TRUE(untracked.ok()) << untracked.error().message();
  for (const auto& bounce : untracked->bounces) EXPECT_FALSE(bounce.tracked_spin_after);
}

TEST(Calibration, BadRecordingsAreNamed) {
  Throw t;
  t.bounces = 3;
  const Track track = throwBall(t);
  const CalibrationOptions options = floorOptions(t);
  {
    const std::vector<TrackedSample> few(track.samples.begin(), track.samples.begin() + 5);
    const auto fit = calibrate(few, options);
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().problem, RecordingProblem::kTooFewSamples) << fit.error().message();
    EXPECT_EQ(fit.error().message(), "too few samples: samples: 5 samples; a fit needs at least 8");
  }
  {
    std::vector<TrackedSample> back = track.samples;
    std::swap(back[20].time, back[21].time);
    const auto fit = calibrate(back, options);
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().problem, RecordingProblem::kStampsGoBack) << fit.error().message();
    EXPECT_EQ(fit.error().field, "samples[21].time");
  }
  {
    // The flight before the first bounce alone.
    std::vector<TrackedSample> flight;
    for (const auto& sample : track.samples) {
      if (sample.time < track.bounces[0].time - 0.01) flight.push_back(sample);
    }
    const auto fit = calibrate(flight, options);
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().problem, RecordingProblem::kNoBounce) << fit.error().message();
  }
  {
    // 30 ms of samples missing around the second bounce (6 sample periods).
    std::vector<TrackedSample> gap;
    for (const auto& sample : track.samples) {
      if (std::abs(sample.time - track.bounces[1].time) > 0.015) gap.push_back(sample);
    }
    const auto fit = calibrate(gap, options);
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().problem, RecordingProblem::kGapAcrossBounce) << fit.error().message();
    EXPECT_EQ(fit.error().field, "bounce 2");
  }
  {
    std::vector<TrackedSample> nan = track.samples;
    nan[3].position.y() = std::nan("");
    const auto fit = calibrate(nan, options);
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().problem, RecordingProblem::kBadValue);
    EXPECT_EQ(fit.error().field, "samples[3].position");
  }
  {
    CalibrationOptions no_plane = options;
    no_plane.planes.clear();
    const auto fit = calibrate(track.samples, no_plane);
    ASSERT_FALSE(fit.ok());
    EXPECT_EQ(fit.error().problem, RecordingProblem::kBadValue);
    EXPECT_EQ(fit.error().field, "planes");
  }
}

// A flight alone gives g and the tracker's noise: a throw's first 0.2 s at 200 Hz with 1 mm of
// noise, gravity fitted.
TEST(Calibration, AFlightGivesGravityAndTheNoise) {
  Throw t;
  t.bounces = 1;
  const Track track = throwBall(t);
  std::vector<TrackedSample> flight;
  for (const auto& sample : track.samples) {
    if (sample.time < track.bounces[0].time) flight.push_back(sample);
  }
  CalibrationOptions options = floorOptions(t);
  options.fit_gravity = true;
  options.gravity = V(0.1, -0.1, -9.0);  // where the fit starts
  const auto fit = fitFlight(flight, options);
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  EXPECT_TRUE(within4(fit->gravity[0], 0.0)) << fit->gravity[0].value;
  EXPECT_TRUE(within4(fit->gravity[1], 0.0)) << fit->gravity[1].value;
  EXPECT_TRUE(within4(fit->gravity[2], -kG)) << fit->gravity[2].value;
  EXPECT_LT(fit->gravity[2].standard_error, 0.5);
  EXPECT_NEAR(fit->noise, t.noise, 0.2 * t.noise);
}

/// A flight under gravity, quadratic drag and the Magnus force, a = g - k |v| v + l |v| (w/|w| x
/// v) (the Magnus force's form: Nathan, Am. J. Phys. 76, 119, 2008), by the classical Runge-Kutta
/// method at 10 us (its error per unit time ~ (k v)^4 h^4, below 1e-12 m here): written here, apart
/// from the core's Dormand-Prince, as the reference.
struct DragState {
  V p;
  V v;
};
DragState rk4(const DragState& x, double k, double h, double l = 0.0, const V& w = V::Zero()) {
  const V g(0, 0, -kG);
  const V axis = w.norm() > 0.0 ? V(w.normalized()) : V::Zero();
  const auto a = [&](const V& v) {
    V out = g - k * v.norm() * v + l * v.norm() * axis.cross(v);
    return out;
  };
  const V k1p = x.v, k1v = a(x.v);
  const V k2p = x.v + 0.5 * h * k1v, k2v = a(x.v + 0.5 * h * k1v);
  const V k3p = x.v + 0.5 * h * k2v, k3v = a(x.v + 0.5 * h * k2v);
  const V k4p = x.v + h * k3v, k4v = a(x.v + h * k3v);
  return DragState{x.p + h / 6 * (k1p + 2 * k2p + 2 * k3p + k4p),
                   x.v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)};
}

/// A table-tennis ball (2.7 g, 20 mm, C_d `cd`, C_L `cl` in air of `density`) thrown at 5 m/s
/// from 0.6 m, spinning at `spin` (40 rad/s about the vertical with C_L 0.3: a Magnus force of
/// 2 m/s^2 sideways at 5 m/s), bouncing twice without friction (e = 0.9; the spin unchanged),
/// flown by rk4 (the crossing bisected to the last bit); 200 Hz, 1 mm of noise drawn from `seed`.
std::pair<std::vector<TrackedSample>, std::vector<double>> throwThroughAir(
    double radius, double mass, double density, double cd, double cl, const V& spin,
    unsigned seed) {
  const double e = 0.9;
  const double area = 3.14159265358979323846 * radius * radius;
  const double k = density * cd * area / (2 * mass);
  const double l = density * cl * area / (2 * mass);
  const double rate = 200.0, step = 1e-5;
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise(0.0, 1e-3);
  DragState x{V(0, 0, 0.6), V(5.0, 0.0, 1.0)};
  std::vector<TrackedSample> samples;
  std::vector<double> bounce_times;
  double time = 0.0;
  int next_sample = 0;
  const double end = 1.6;
  const auto sample = [&](double s) {
    samples.push_back({next_sample / rate,
                       rk4(x, k, s, l, spin).p + V(noise(random), noise(random), noise(random)),
                       std::nullopt});
    ++next_sample;
  };
  while (time < end) {
    DragState y = rk4(x, k, step, l, spin);
    if (y.p.z() < radius && bounce_times.size() < 2) {
      double low = 0.0, high = step;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (low + high);
        (rk4(x, k, mid, l, spin).p.z() >= radius ? low : high) = mid;
      }
      while (next_sample / rate <= time + low) sample(next_sample / rate - time);
      x = rk4(x, k, low, l, spin);
      time += low;
      bounce_times.push_back(time);
      x.v.z() = -e * x.v.z();
      continue;
    }
    while (next_sample / rate <= time + step && next_sample / rate <= end) {
      sample(next_sample / rate - time);
    }
    x = y;
    time += step;
  }
  return {samples, bounce_times};
}

// A table-tennis ball (2.7 g, 20 mm, C_d 0.5 in air of 1.2 kg/m^3: k = 0.14 1/m, drag 3.5 m/s^2
// at 5 m/s) thrown at 5 m/s and bouncing twice (e = 0.9, no friction): C_d and e are recovered
// with drag fitted, starting from C_d 0.47. 200 Hz, 1 mm of noise.
TEST(Calibration, DragCoefficientFromTheFlights) {
  const double e = 0.9, radius = 0.02, mass = 0.0027, density = 1.2, cd = 0.5;
  const auto [samples, bounce_times] =
      throwThroughAir(radius, mass, density, cd, 0.0, V::Zero(), 5);
  ASSERT_EQ(bounce_times.size(), 2u);
  CalibrationOptions options;
  options.planes = {Plane{V(0, 0, 1), 0.0}};
  options.radius = radius;
  options.drag = true;
  options.fit_drag = true;
  options.air_density = density;
  options.mass = mass;
  options.drag_coefficient = 0.47;
  options.spin_before = V::Zero();
  options.max_bounces = 2;
  const auto fit = calibrate(samples, options);
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  ASSERT_EQ(fit->bounces.size(), 2u);
  ASSERT_TRUE(fit->drag_coefficient.has_value());
  EXPECT_TRUE(within4(*fit->drag_coefficient, cd))
      << fit->drag_coefficient->value << " +- " << fit->drag_coefficient->standard_error;
  EXPECT_LT(fit->drag_coefficient->standard_error, 0.05);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_TRUE(within4(fit->bounces[j].restitution, e)) << fit->bounces[j].restitution.value;
    EXPECT_TRUE(within4(fit->bounces[j].time, bounce_times[j])) << fit->bounces[j].time.value;
  }
  EXPECT_NEAR(fit->noise, 1e-3, 1e-4);
  std::printf("C_d %.5f +- %.5f (truth %.2f), e %.5f %.5f, %zu samples, %d iterations\n",
              fit->drag_coefficient->value, 1.96 * fit->drag_coefficient->standard_error, cd,
              fit->bounces[0].restitution.value, fit->bounces[1].restitution.value,
              fit->samples_used, fit->iterations);
}

// The Magnus force in the fit: C_L recovered within 4 standard errors from 0.2 (fit_lift), and with
// the scene's C_L given, e and the instants; without `magnus` the sideways curve is left in the
// residuals (the noise read 6.5 mm for 1); magnus without the spin before is named.
TEST(Calibration, LiftCoefficientFromACurvingBallsFlights) {
  const double radius = 0.02, mass = 0.0027, density = 1.2, cd = 0.5, cl = 0.3;
  const V spin(0, 0, 40);
  const auto [samples, bounce_times] = throwThroughAir(radius, mass, density, cd, cl, spin, 6);
  ASSERT_EQ(bounce_times.size(), 2u);
  CalibrationOptions options;
  options.planes = {Plane{V(0, 0, 1), 0.0}};
  options.radius = radius;
  options.drag = true;
  options.air_density = density;
  options.mass = mass;
  options.drag_coefficient = cd;
  options.magnus = true;
  options.fit_lift = true;
  options.lift_coefficient = 0.2;
  options.spin_before = spin;
  options.max_bounces = 2;
  const auto fit = calibrate(samples, options);
  ASSERT_TRUE(fit.ok()) << fit.error().message();
  ASSERT_EQ(fit->bounces.size(), 2u);
  ASSERT_TRUE(fit->lift_coefficient.has_value());
  EXPECT_FALSE(fit->drag_coefficient.has_value());
  EXPECT_TRUE(within4(*fit->lift_coefficient, cl))
      << fit->lift_coefficient->value << " +- " << fit->lift_coefficient->standard_error;
  EXPECT_LT(fit->lift_coefficient->standard_error, 0.01);
  EXPECT_NEAR(fit->noise, 1e-3, 1e-4);
  std::printf("C_L %.5f +- %.5f (truth %.2f), %zu samples, %d iterations\n",
              fit->lift_coefficient->value, 1.96 * fit->lift_coefficient->standard_error, cl,
              fit->samples_used, fit->iterations);

  options.fit_lift = false;
  options.lift_coefficient = cl;
  const auto given = calibrate(samples, options);
  ASSERT_TRUE(given.ok()) << given.error().message();
  EXPECT_FALSE(given->lift_coefficient.has_value());
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_TRUE(within4(given->bounces[j].restitution, 0.9)) << given->bounces[j].restitution.value;
    EXPECT_TRUE(within4(given->bounces[j].time, bounce_times[j])) << given->bounces[j].time.value;
  }
  EXPECT_NEAR(given->noise, 1e-3, 1e-4);

  options.magnus = false;
  const auto without = calibrate(samples, options);
  ASSERT_TRUE(without.ok()) << without.error().message();
  EXPECT_GT(without->noise, 5e-3);

  options.magnus = true;
  options.spin_before.reset();
  const auto unknown_spin = calibrate(samples, options);
  ASSERT_FALSE(unknown_spin.ok());
  EXPECT_EQ(unknown_spin.error().problem, RecordingProblem::kBadValue);
  EXPECT_EQ(unknown_spin.error().field, "spin_before");
  // The fitted motion replayed without the spin it was flown with: none (not a spin made up).
  EXPECT_TRUE(fittedPosition(*given, options, 0.5).hasNaN());
}

}  // namespace
}  // namespace collision_response::core

#include "collision_response/ros/live_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "collision_response/core/validation.h"

namespace collision_response {

namespace {

/// `value` with enough decimals for the two leading digits of `half` (an interval's half width),
/// 3 to 10 of them, as `rosrun collision_response calibrate` prints.
std::string decimal(double value, double half) {
  int digits = 10;
  if (half > 0.0 && std::isfinite(half)) {
    digits = std::clamp(1 - static_cast<int>(std::floor(std::log10(half))), 3, 10);
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

/// `value` with `digits` significant digits.
std::string significant(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

/// "e 0.90002 (95 %: 0.89990 to 0.90014)".
std::string restitutionText(const core::Estimate& e) {
  const double half = e.high() - e.value;
  return "e " + decimal(e.value, half) + " (95 %: " + decimal(e.low(), half) + " to " +
         decimal(e.high(), half) + ")";
}

/// "mu 0.0301 (95 %: 0.0287 to 0.0315)", and/or "mu >= 0.0123 (...)", or "mu: nothing (...)":
/// what the pair's bounces say of friction (calibration.h, Coefficients).
std::string frictionText(const core::Coefficients& c) {
  std::string text;
  if (c.friction) {
    const double half = c.friction->high() - c.friction->value;
    text = "mu " + decimal(c.friction->value, half) +
           " (95 %: " + decimal(c.friction->low(), half) + " to " +
           decimal(c.friction->high(), half) + ")";
  }
  if (c.friction_lower_bound) {
    text += std::string(text.empty() ? "" : "; ") +
            "mu >= " + decimal(*c.friction_lower_bound, 0.005) +
            " (a contact that stopped slipping, or the spin before unknown: a lower bound only)";
  }
  if (text.empty()) text = "mu: nothing (the contact did not slide)";
  return text;
}

/// One obstacle pair a plane material: the materials of the planes the fit's bounces were on, in
/// the order first met.
std::vector<std::string> materialsBouncedOn(const core::Calibration& fit,
                                            const std::vector<std::string>& plane_materials) {
  std::vector<std::string> materials;
  for (const core::BounceEstimate& bounce : fit.bounces) {
    const std::string& material = plane_materials[bounce.plane];
    if (std::find(materials.begin(), materials.end(), material) == materials.end()) {
      materials.push_back(material);
    }
  }
  return materials;
}

/// The fit's bounces (indices) on the planes of `material`: its pair's bounces together.
std::vector<std::size_t> bouncesOn(const core::Calibration& fit,
                                   const std::vector<std::string>& plane_materials,
                                   const std::string& material) {
  std::vector<std::size_t> which;
  for (std::size_t j = 0; j < fit.bounces.size(); ++j) {
    if (plane_materials[fit.bounces[j].plane] == material) which.push_back(j);
  }
  return which;
}

}  // namespace

CalibrationWindow::CalibrationWindow(std::size_t bodies, double seconds, std::size_t max_samples)
    : seconds_(seconds > 0.0 ? seconds : 0.0), capacity_(1) {
  while (capacity_ * 2 <= max_samples) capacity_ *= 2;
  if (enabled()) last_.assign(bodies, 0);
}

void CalibrationWindow::append(std::size_t body, double time, const Eigen::Vector3d& position) {
  if (end_ - begin_ == log_.size()) {
    if (log_.size() < capacity_) {
      // Doubled, each held entry moved to its place in the larger ring.
      std::vector<Entry> grown(std::min(capacity_, std::max<std::size_t>(1024, 2 * log_.size())));
      for (std::uint64_t s = begin_; s < end_; ++s) grown[s & (grown.size() - 1)] = entry(s);
      log_ = std::move(grown);
    } else {
      ++begin_;  // full: the oldest makes room, never the newest
    }
  }
  log_[end_ & (log_.size() - 1)] = Entry{time, position, last_[body]};
  last_[body] = ++end_;
}

void CalibrationWindow::record(const std::vector<core::BodyStateSample>& samples) {
  if (!enabled() || samples.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const core::BodyStateSample& sample : samples) {
    if (sample.body >= last_.size() || !std::isfinite(sample.time)) continue;
    const std::uint64_t last = last_[sample.body];
    if (last > begin_ && !(sample.time > entry(last - 1).time)) continue;
    if (begin_ == end_ || sample.time > newest_) newest_ = sample.time;
    append(sample.body, sample.time, sample.position);
  }
  while (begin_ < end_ && entry(begin_).time < newest_ - seconds_) ++begin_;
}

void CalibrationWindow::clear() {
  if (!enabled()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  begin_ = end_;
}

std::vector<core::TrackedSample> CalibrationWindow::copy(std::size_t body) const {
  std::vector<core::TrackedSample> samples;
  std::lock_guard<std::mutex> lock(mutex_);
  if (body >= last_.size()) return samples;
  const double since = newest_ - seconds_;
  for (std::uint64_t link = last_[body]; link > begin_ && samples.size() < kMaxSamplesPerBody;) {
    const Entry& held = entry(link - 1);
    if (held.time < since) break;
    samples.push_back({held.time, held.position, std::nullopt});
    link = held.previous;
  }
  std::reverse(samples.begin(), samples.end());
  return samples;
}

std::size_t CalibrationWindow::size(std::size_t body) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t count = 0;
  if (body >= last_.size()) return count;
  for (std::uint64_t link = last_[body]; link > begin_; link = entry(link - 1).previous) ++count;
  return count;
}

std::size_t CalibrationWindow::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<std::size_t>(end_ - begin_);
}

LiveCalibration::LiveCalibration(const core::Scene& scene, double window_seconds)
    : window_(scene.bodies.size(), window_seconds) {
  // The scene's own motion model and fixed planes, read as `rosrun collision_response calibrate`
  // reads them (core::sceneCalibration, one place for both); a scene the fit cannot take is
  // refused at each request, after its body is named.
  const auto reading = core::sceneCalibration(scene);
  if (reading) {
    options_ = reading->options;
    plane_materials_ = reading->plane_materials;
  } else {
    scene_refusal_ = "body: " + reading.error().reason;
  }
  if (!window_.enabled()) return;  // no body is fitted: nothing more kept
  bodies_.reserve(scene.bodies.size());
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const core::BodySpec& spec = scene.bodies[i];
    // What the fit reads of the body (core::bodyCalibration), and its names.
    bodies_.push_back({spec.id, spec.material, core::bodyCalibration(spec)});
    body_index_.emplace(spec.id, i);
  }
}

namespace {

/// The request's spin before the window's first bounce: none (empty), or 3 finite values; an
/// error names `spin_before`.
core::Expected<std::optional<Eigen::Vector3d>> spinBeforeOf(
    const EstimateRestitution::Request& request) {
  if (request.spin_before.empty()) return std::optional<Eigen::Vector3d>{};
  if (request.spin_before.size() != 3) {
    return core::Error{"spin_before",
                       "must be empty (unknown) or 3 values (rad/s, the fixed frame), got " +
                           std::to_string(request.spin_before.size())};
  }
  const Eigen::Vector3d spin(request.spin_before[0], request.spin_before[1],
                             request.spin_before[2]);
  if (!spin.allFinite()) return core::Error{"spin_before", "must be finite"};
  return std::optional<Eigen::Vector3d>{spin};
}

/// The response's e, mu and bounces: one pair's.
void answerWith(const core::Coefficients& c, EstimateRestitution::Response& response) {
  response.restitution = c.restitution.value;
  response.restitution_low = c.restitution.low();
  response.restitution_high = c.restitution.high();
  response.bounces = static_cast<std::int32_t>(c.bounces);
  response.friction_known = c.friction.has_value();
  if (c.friction) {
    response.friction = c.friction->value;
    response.friction_low = c.friction->low();
    response.friction_high = c.friction->high();
  } else {
    response.friction = response.friction_low = response.friction_high = 0.0;
  }
  response.friction_lower_bound = c.friction_lower_bound.value_or(0.0);
}

}  // namespace

void LiveCalibration::answer(const EstimateRestitution::Request& request,
                             EstimateRestitution::Response& response,
                             std::vector<PairEstimate>& pairs) const {
  response = EstimateRestitution::Response();
  const auto refuse = [&](const std::string& text) {
    response.success = false;
    response.message = text;
  };
  if (request.max_bounces < 0) {
    return refuse("max_bounces: must be 0 (every bounce in the window) or more, got " +
                  std::to_string(request.max_bounces));
  }
  const auto spin_before = spinBeforeOf(request);
  if (!spin_before) return refuse(spin_before.error().message());
  if (!window_.enabled()) {
    return refuse("body: ~calibration_window is 0: the node keeps no states to fit '" +
                  request.body + "' from (set it to the seconds of states to keep)");
  }
  const auto found = body_index_.find(request.body);
  if (found == body_index_.end()) {
    return refuse("body: '" + request.body + "' is not a body of the scene (" +
                  std::to_string(bodies_.size()) + " bodies; ids are the scene's bodies[].id)");
  }
  const Body& body = bodies_[found->second];
  if (!scene_refusal_.empty()) return refuse(scene_refusal_);
  // The window copied under its own lock; the fit without any.
  const std::vector<core::TrackedSample> samples = window_.copy(found->second);
  const std::string window_text =
      "~calibration_window " + core::formatNumber(window_.seconds()) + " s, at most " +
      std::to_string(CalibrationWindow::kMaxSamplesPerBody) + " states of a body";
  if (samples.empty()) {
    return refuse("body: no state of '" + body.id + "' in the window (" + window_text + ")");
  }
  core::CalibrationOptions options = core::forBody(options_, body.fit);
  options.spin_before = *spin_before;
  std::string what = "body '" + body.id + "', " + std::to_string(samples.size()) + " states over " +
                     decimal(samples.back().time - samples.front().time, 0.01) + " s (" +
                     window_text + ")";
  auto fit = core::calibrate(samples, options);
  if (!fit) return refuse(what + ": " + fit.error().message());
  // Friction from the whole window's fit: the spin before its first bounce is the one given, and
  // the fit carries it (and its uncertainty) to each later bounce.
  const auto whole = fit;
  std::size_t skipped = 0;
  const auto wanted = static_cast<std::size_t>(request.max_bounces);
  if (wanted > 0 && fit->bounces.size() > wanted) {
    // The most recent bounces: the states from just after the one before them, fitted again.
    skipped = fit->bounces.size() - wanted;
    const double after = fit->bounces[skipped - 1].time.value;
    std::vector<core::TrackedSample> recent;
    for (const core::TrackedSample& sample : samples) {
      if (sample.time > after) recent.push_back(sample);
    }
    options.max_bounces = wanted;
    options.spin_before.reset();  // the spin there is the whole fit's: friction is read from it
    what += ", the last " + std::to_string(wanted) + " bounces from its " +
            std::to_string(recent.size()) + " states after bounce " + std::to_string(skipped) +
            " (friction: those bounces of the whole window's fit)";
    fit = core::calibrate(recent, options);
    if (!fit) return refuse(what + ": " + fit.error().message());
  }
  std::string text;
  std::size_t most = 0;
  const std::vector<std::string> materials = materialsBouncedOn(*fit, plane_materials_);
  for (const std::string& material : materials) {
    const std::vector<std::size_t> which = bouncesOn(*fit, plane_materials_, material);
    PairEstimate estimate{"[" + body.material + ", " + material + "]", body.id,
                          core::combine(*fit, which), ""};
    core::Coefficients& c = estimate.coefficients;
    // The pair's friction: its bounces among the whole window's fit's last ones.
    std::vector<std::size_t> in_whole;
    for (const std::size_t j : bouncesOn(*whole, plane_materials_, material)) {
      if (j >= skipped) in_whole.push_back(j);
    }
    const core::Coefficients friction = core::combine(*whole, in_whole);
    c.friction = friction.friction;
    c.friction_lower_bound = friction.friction_lower_bound;
    const std::string bounces =
        std::to_string(c.bounces) + " bounce" + (c.bounces == 1 ? "" : "s") + " at " +
        decimal(c.slowest_approach, 0.01) + " to " + decimal(c.fastest_approach, 0.01) + " m/s";
    estimate.summary = restitutionText(c.restitution) + ", " + frictionText(c) + ", " + bounces +
                       " of '" + body.id + "'";
    text += "; pair " + estimate.pair + ": " + bounces + ": " + restitutionText(c.restitution) +
            (c.bounces > 1 ? ", spread " + decimal(c.restitution_spread, 0.1) +
                                 " (about 1 when one e fits them all)"
                           : " (one bounce: no spread)") +
            ", " + frictionText(c);
    if (c.bounces > most) {
      most = c.bounces;
      answerWith(c, response);
    }
    pairs.push_back(std::move(estimate));
  }
  response.success = true;
  response.message = what + ", tracker noise " + significant(fit->noise * 1e3, 3) + " mm" + text;
  if (materials.size() > 1) {
    response.message += "; the response's e is the pair with the most bounces'";
  }
}

}  // namespace collision_response

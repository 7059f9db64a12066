#include "pf_localization/core/sensor/sensor_health.h"

#include <algorithm>
#include <cstdio>
#include <utility>

namespace pf {
namespace {

// The weight of a new interval in the averaged period: about the last ten.
constexpr double kPeriodSmoothing = 0.1;

}  // namespace

const char* toString(SensorState state) {
  switch (state) {
    case SensorState::kWaiting:
      return "waiting";
    case SensorState::kOk:
      return "ok";
    case SensorState::kSilent:
      return "silent";
    case SensorState::kBlocked:
      return "blocked";
  }
  return "unknown";
}

SensorHealth::SensorHealth(std::vector<std::string> names)
    : names_(std::move(names)), tracks_(names_.size()) {}

void SensorHealth::add(std::string name) {
  names_.push_back(std::move(name));
  tracks_.emplace_back();
}

void SensorHealth::observe(std::size_t sensor, double t, std::size_t beams, std::size_t valid,
                           double fit) {
  if (sensor >= tracks_.size()) return;
  Track& k = tracks_[sensor];
  if (k.seen && t > k.last) {
    const double interval = t - k.last;
    k.period = k.period > 0.0 ? (1.0 - kPeriodSmoothing) * k.period + kPeriodSmoothing * interval
                              : interval;
  }
  k.seen = true;
  k.last = std::max(k.last, t);
  k.valid_share = beams > 0 ? static_cast<double>(valid) / static_cast<double>(beams) : 0.0;
  k.fit_share = fit;
}

std::vector<SensorStatus> SensorHealth::status(double now) const {
  std::vector<SensorStatus> out(names_.size());
  for (std::size_t i = 0; i < names_.size(); ++i) {
    const Track& k = tracks_[i];
    SensorStatus& s = out[i];
    s.name = names_[i];
    if (!k.seen) continue;
    s.rate_hz = k.period > 0.0 ? 1.0 / k.period : 0.0;
    s.age_s = std::max(0.0, now - k.last);
    s.valid_share = k.valid_share;
    s.fit_share = k.fit_share;
    s.state = s.age_s > kSilentAfter          ? SensorState::kSilent
              : k.valid_share < kBlockedBelow ? SensorState::kBlocked
                                              : SensorState::kOk;
  }
  return out;
}

std::string SensorHealth::missing(double now) const {
  std::string out;
  for (const SensorStatus& s : status(now)) {
    if (s.state != SensorState::kSilent && s.state != SensorState::kBlocked) continue;
    char detail[64];
    if (s.state == SensorState::kSilent) {
      std::snprintf(detail, sizeof detail, " (silent %.1f s)", s.age_s);
    } else {
      std::snprintf(detail, sizeof detail, " (blocked: %.0f %% of its beams read)",
                    100.0 * s.valid_share);
    }
    out += (out.empty() ? "" : ", ") + s.name + detail;
  }
  return out;
}

}  // namespace pf

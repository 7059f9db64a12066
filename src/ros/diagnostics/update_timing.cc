#include "pf_localization/ros/diagnostics/update_timing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace pf_ros {
namespace {

void add(diagnostic_msgs::DiagnosticStatus* status, const std::string& key,
         const std::string& value) {
  diagnostic_msgs::KeyValue kv;
  kv.key = key;
  kv.value = value;
  status->values.push_back(kv);
}

void addMs(diagnostic_msgs::DiagnosticStatus* status, const std::string& prefix,
           const RollingPercentiles& r) {
  for (const auto& [suffix, value] : {std::pair<const char*, double>{"_p50_ms", r.percentile(0.5)},
                                      std::pair<const char*, double>{"_p95_ms", r.percentile(0.95)},
                                      std::pair<const char*, double>{"_max_ms", r.max()}}) {
    char text[64];  // a duration in ms: a handful of digits, truncated past 63
    std::snprintf(text, sizeof text, "%.1f", value * 1e3);
    add(status, prefix + suffix, text);
  }
}

}  // namespace

UpdateTiming::UpdateTiming(const UpdateTimingOptions& options)
    : latency_(options.window), age_(options.window), update_(options.window) {}

void UpdateTiming::addUpdate(double latency_s, double age_s, double update_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  latency_.add(latency_s);
  age_.add(age_s);
  update_.add(update_s);
}

double UpdateTiming::updateTimeP95() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return update_.percentile(0.95);
}

void UpdateTiming::addTo(diagnostic_msgs::DiagnosticStatus* status, std::uint64_t dropped,
                         std::size_t particle_cap) const {
  std::lock_guard<std::mutex> lock(mutex_);
  addMs(status, "latency", latency_);
  addMs(status, "scan_age", age_);
  addMs(status, "update_time", update_);
  add(status, "dropped_scans", std::to_string(dropped));
  if (particle_cap > 0) add(status, "particle_cap", std::to_string(particle_cap));
}

}  // namespace pf_ros

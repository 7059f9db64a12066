#include "pf_localization/core/recovery/floor_search.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace pf {

double explainedShare(const DistanceField& field, const ScanGroup& scans, const Pose2& robot,
                      double distance) {
  std::size_t readings = 0, explained = 0;
  for (const LaserScan& scan : scans) {
    const Pose2 sensor = compose(compose(robot, scan.robot_offset), scan.sensor_pose);
    for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
      const float r = scan.ranges[i];
      if (!isReading(r, scan.range_min, scan.range_max)) continue;
      const double a = sensor.yaw + scan.angle_min + static_cast<double>(i) * scan.angle_increment;
      ++readings;
      explained +=
          field.distanceAt(sensor.x + r * std::cos(a), sensor.y + r * std::sin(a)) <= distance;
    }
  }
  return readings == 0 ? 0.0 : static_cast<double>(explained) / static_cast<double>(readings);
}

FloorSearch::FloorSearch(const ParticleFilterParams& params, std::vector<PreparedMap> maps,
                         std::vector<std::string> names, FloorSearchParams search)
    : params_(search), names_(std::move(names)) {
  if (maps.empty()) throw std::invalid_argument("floor search: no floor");
  for (PreparedMap& map : maps) {
    filters_.push_back(std::make_unique<ParticleFilter>(params));
    filters_.back()->setMap(std::move(map));
    filters_.back()->initializeUniform();
  }
  localized_run_.assign(filters_.size(), 0);
  fits_.resize(filters_.size());
}

void FloorSearch::update(const Pose2& odom, const ScanGroup& scans) {
  for (std::size_t i = 0; i < filters_.size(); ++i) {
    const UpdateReport report = filters_[i]->update(odom, scans);
    if (!report.updated) continue;
    std::vector<double>& fits = fits_[i];
    const ParticleFilter& f = *filters_[i];
    fits.push_back(
        explainedShare(f.sensorModel()->field(), scans, f.estimate().pose, params_.fit_distance));
    if (fits.size() > static_cast<std::size_t>(params_.fit_updates)) fits.erase(fits.begin());
    const bool localized = filters_[i]->confidence().state == LocalizationState::kLocalized;
    localized_run_[i] = localized ? localized_run_[i] + 1 : 0;
  }
}

double FloorSearch::fit(std::size_t floor) const {
  const std::vector<double>& fits = fits_[floor];
  double sum = 0.0;
  for (double f : fits) sum += f;
  return fits.empty() ? 0.0 : sum / static_cast<double>(fits.size());
}

std::string FloorSearch::nameOf(std::size_t floor) const {
  return floor < names_.size() ? "floor '" + names_[floor] + "'" : "floor " + std::to_string(floor);
}

FloorSearch::Verdict FloorSearch::verdict() const {
  std::size_t best = 0;  // the floor that explains the scans best
  for (std::size_t i = 1; i < filters_.size(); ++i) {
    if (fit(i) > fit(best)) best = i;
  }
  for (std::size_t i = 0; i < filters_.size(); ++i) {
    if (i == best || fit(best) - fit(i) >= params_.min_fit_margin) continue;
    char shares[64];
    std::snprintf(shares, sizeof shares, " %.0f %% of the beams, ", 100.0 * fit(best));
    std::string reason = nameOf(best) + " explains" + shares + nameOf(i);
    std::snprintf(shares, sizeof shares, " %.0f %%: cannot tell them apart yet", 100.0 * fit(i));
    return {std::nullopt, reason + shares};
  }
  if (localized_run_[best] == 0) {
    return {std::nullopt, nameOf(best) + " explains the scans best, but is not localized yet"};
  }
  if (localized_run_[best] < params_.found_updates) {
    return {std::nullopt, nameOf(best) + " fits; waiting for " +
                              std::to_string(params_.found_updates - localized_run_[best]) +
                              " more updates"};
  }
  return {best, nameOf(best) + " fits, and no other does"};
}

std::vector<PreparedMap> FloorSearch::release() {
  std::vector<PreparedMap> maps;
  for (auto& filter : filters_) maps.push_back(std::move(*filter->releaseMap()));
  filters_.clear();
  localized_run_.clear();
  fits_.clear();
  return maps;
}

}  // namespace pf

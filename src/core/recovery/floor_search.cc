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

uint64_t floorSeed(uint64_t seed, std::size_t floor) {
  return seed + static_cast<uint64_t>(floor) * 0x9E3779B97F4A7C15ull;
}

FloorSearch::FloorSearch(const ParticleFilterParams& params, std::vector<PreparedMap> maps,
                         std::vector<std::string> names, FloorSearchParams search)
    : params_(search), names_(std::move(names)) {
  if (maps.empty()) throw std::invalid_argument("floor search: no floor");
  for (PreparedMap& map : maps) {
    ParticleFilterParams floor_params = params;
    floor_params.seed = floorSeed(params.seed, filters_.size());
    filters_.push_back(std::make_unique<ParticleFilter>(floor_params));
    filters_.back()->setMap(std::move(map));
    filters_.back()->initializeUniform();
  }
  lead_run_.assign(filters_.size(), 0);
  fits_.resize(filters_.size());
}

void FloorSearch::update(const Pose2& odom, const ScanGroup& scans) {
  bool updated = false;
  for (std::size_t i = 0; i < filters_.size(); ++i) {
    const UpdateReport report = filters_[i]->update(odom, scans);
    if (!report.updated) continue;
    updated = true;
    std::vector<double>& fits = fits_[i];
    const ParticleFilter& f = *filters_[i];
    fits.push_back(
        explainedShare(f.sensorModel()->field(), scans, f.estimate().pose, params_.fit_distance));
    if (fits.size() > static_cast<std::size_t>(params_.fit_updates)) fits.erase(fits.begin());
  }
  if (!updated) return;
  const std::size_t best = bestFit();
  const bool leads = !closeTo(best);
  for (std::size_t i = 0; i < filters_.size(); ++i) {
    lead_run_[i] = i == best && leads ? lead_run_[i] + 1 : 0;
  }
}

std::size_t FloorSearch::bestFit() const {
  std::size_t best = 0;
  for (std::size_t i = 1; i < filters_.size(); ++i) {
    if (fit(i) > fit(best)) best = i;
  }
  return best;
}

std::optional<std::size_t> FloorSearch::closeTo(std::size_t best) const {
  for (std::size_t i = 0; i < filters_.size(); ++i) {
    if (i != best && fit(best) - fit(i) < params_.min_fit_margin) return i;
  }
  return std::nullopt;
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
  const std::size_t best = bestFit();  // the floor that explains the scans best
  if (const std::optional<std::size_t> other = closeTo(best)) {
    char shares[64];
    std::snprintf(shares, sizeof shares, " %.0f %% of the beams, ", 100.0 * fit(best));
    std::string reason = nameOf(best) + " explains" + shares + nameOf(*other);
    std::snprintf(shares, sizeof shares, " %.0f %%: cannot tell them apart yet",
                  100.0 * fit(*other));
    return {std::nullopt, reason + shares};
  }
  if (lead_run_[best] < params_.found_updates) {
    return {std::nullopt, nameOf(best) + " explains the scans best; waiting for " +
                              std::to_string(params_.found_updates - lead_run_[best]) +
                              " more updates"};
  }
  if (filters_[best]->confidence().state != LocalizationState::kLocalized) {
    return {std::nullopt, nameOf(best) + " explains the scans best, but is not localized yet"};
  }
  return {best, nameOf(best) + " fits, and no other does"};
}

std::vector<PreparedMap> FloorSearch::release() {
  std::vector<PreparedMap> maps;
  for (auto& filter : filters_) maps.push_back(std::move(*filter->releaseMap()));
  filters_.clear();
  lead_run_.clear();
  fits_.clear();
  return maps;
}

}  // namespace pf

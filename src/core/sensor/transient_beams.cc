#include "pf_localization/core/sensor/transient_beams.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pf {
namespace {

constexpr float kNoReading = std::numeric_limits<float>::infinity();

// A beam's range, or inf when it has none (as selectBeams judges it).
float rangeOf(const LaserScan& scan, std::size_t i) {
  const float r = scan.ranges[i];
  return isReading(r, scan.range_min, scan.range_max) ? r : kNoReading;
}

}  // namespace

bool TransientBeams::Background::sameLayout(const LaserScan& scan) const {
  return scan.ranges.size() == ranges.size() && scan.angle_min == angle_min &&
         scan.angle_increment == angle_increment && scan.sensor_pose.x == sensor_pose.x &&
         scan.sensor_pose.y == sensor_pose.y && scan.sensor_pose.yaw == sensor_pose.yaw;
}

int TransientBeams::maskScan(const LaserScan& scan, const Pose2& at, const OnMap& on_map,
                             Background* bg, std::vector<float>* masked) {
  const std::size_t n = scan.ranges.size();
  const bool still = bg->sameLayout(scan) &&
                     std::hypot(at.x - bg->at.x, at.y - bg->at.y) <= kStillDistance &&
                     std::fabs(angleDiff(at.yaw, bg->at.yaw)) <= kStillAngle;
  if (!still) {
    bg->ranges.resize(n);
    for (std::size_t i = 0; i < n; ++i) bg->ranges[i] = rangeOf(scan, i);
    bg->in_a_row.assign(n, 0);
    bg->at = at;
    bg->angle_min = scan.angle_min;
    bg->angle_increment = scan.angle_increment;
    bg->sensor_pose = scan.sensor_pose;
    return 0;
  }
  // What the background saw along each of this scan's beams: its end
  // points moved into this scan's frame, the nearest in each beam (NaN
  // where none falls: such a beam is never masked).
  std::vector<float>& seen = bg->seen;
  seen.assign(n, std::numeric_limits<float>::quiet_NaN());
  const Pose2 rel = between(at, bg->at);
  for (std::size_t j = 0; j < n; ++j) {
    const double bearing = scan.angle_min + static_cast<double>(j) * scan.angle_increment;
    // A beam without a reading says nothing of how far the lidar saw: it may
    // have been a dropout as well as open space.
    const double r = bg->ranges[j];
    if (!std::isfinite(r)) continue;
    const Pose2 end = compose(rel, {r * std::cos(bearing), r * std::sin(bearing), 0.0});
    const double range = std::hypot(end.x, end.y), angle = std::atan2(end.y, end.x);
    double beams = angleDiff(angle, scan.angle_min) / scan.angle_increment;
    if (beams < -0.5) beams += 2.0 * M_PI / std::fabs(scan.angle_increment);  // past a half turn
    const long k = std::lround(beams);
    if (k < 0 || k >= static_cast<long>(n)) continue;
    float& v = seen[static_cast<std::size_t>(k)];
    if (!(v <= static_cast<float>(range))) v = static_cast<float>(range);
  }
  const std::size_t reach = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::ceil(kBearingTolerance / std::fabs(scan.angle_increment))));
  int count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // Shorter than what the background saw within `reach` beams of it, so
    // that a depth edge a beam slid across is not taken for something that
    // moved in.
    const float r = rangeOf(scan, i);
    bool shorter = std::isfinite(r);
    for (std::size_t j = i > reach ? i - reach : 0; shorter && j <= i + reach && j < n; ++j) {
      shorter = r < seen[j] - static_cast<float>(kMargin);
    }
    if (!shorter) {
      bg->in_a_row[i] = 0;
      continue;
    }
    // Short for kMaxMaskedScans scans in a row: what it sees has stayed.
    if (bg->in_a_row[i] >= kMaxMaskedScans) continue;
    if (on_map) {
      const double bearing = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
      const Pose2 end = compose(compose(scan.robot_offset, scan.sensor_pose),
                                {r * std::cos(bearing), r * std::sin(bearing), 0.0});
      if (on_map(end.x, end.y)) continue;
    }
    ++bg->in_a_row[i];
    if (count == 0) *masked = scan.ranges;
    (*masked)[i] = std::numeric_limits<float>::quiet_NaN();
    ++count;
  }
  return count;
}

ScanGroup TransientBeams::mask(const Pose2& odom, const ScanGroup& scans, const OnMap& on_map,
                               std::vector<LaserScan>* storage) {
  masked_ = 0;
  if (!odom.isFinite()) return scans;
  if (backgrounds_.size() < scans.size()) backgrounds_.resize(scans.size());
  std::vector<float> ranges;
  std::vector<std::pair<std::size_t, std::vector<float>>> changed;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const LaserScan& scan = scans[s];
    if (validateScan(scan)) continue;
    const Pose2 at = compose(compose(odom, scan.robot_offset), scan.sensor_pose);
    const int count = maskScan(scan, at, on_map, &backgrounds_[s], &ranges);
    if (count == 0) continue;
    masked_ += count;
    changed.emplace_back(s, std::move(ranges));
    ranges.clear();
  }
  if (changed.empty()) return scans;
  storage->assign(scans.begin(), scans.end());
  for (auto& [s, masked_ranges] : changed) (*storage)[s].ranges = std::move(masked_ranges);
  return ScanGroup(*storage);
}

}  // namespace pf

// The scans of one filter update: the latest scan of each sensor since the
// last update (two safety lidars front and rear, a 3D lidar reduced to a
// scan), each placed on the robot as it stood at the update. Sensors run at
// their own rates and are not synchronised: a scan taken before the update
// carries LaserScan::robot_offset, the robot's pose at its stamp in the
// robot's frame at the update (from the odometry), so its beams start where
// that sensor was. Two half views then score as one full view, without a
// merged scan that pretends every beam came from one point.
//
// Each scan is prepared with its own beam budget and range limits and scored
// on its own (its own range_max scales z_rand), its log-likelihood weighted
// by LaserScan::weight; the fit of the estimate (scan_refiner.h) takes every
// scan's end points together. A group of one scan is exactly the scan.
#pragma once

#include <cstddef>
#include <vector>

#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

/// A view of one or more scans (not owned: they must outlive the group).
class ScanGroup {
 public:
  /// One scan: what every single-sensor robot gives.
  ScanGroup(const LaserScan& scan) : scans_(&scan), count_(1) {}  // NOLINT: implicit on purpose
  ScanGroup(const std::vector<LaserScan>& scans) : scans_(scans.data()), count_(scans.size()) {}

  std::size_t size() const { return count_; }
  const LaserScan& operator[](std::size_t i) const { return scans_[i]; }
  const LaserScan* begin() const { return scans_; }
  const LaserScan* end() const { return scans_ + count_; }

 private:
  const LaserScan* scans_;
  std::size_t count_;
};

/// The scans of a group prepared by `model`, each with at most `max_beams`
/// beams (<= 0: all; the model's own budget when omitted).
std::vector<PreparedScan> prepareScans(const SensorModel& model, const ScanGroup& scans);
std::vector<PreparedScan> prepareScans(const SensorModel& model, const ScanGroup& scans,
                                       int max_beams);

/// Every prepared scan's end points in one scan, for the scan fit, which
/// needs only end points. One scan is returned as it is.
PreparedScan joinedEndPoints(std::vector<PreparedScan> scans);

/// The beams of all the scans together.
std::size_t beamCount(const std::vector<PreparedScan>& scans);
/// The beams dropped as invalid, over all the scans.
int droppedBeams(const std::vector<PreparedScan>& scans);

/// The share of all the scans' beams whose end point, placed from `pose`,
/// lies within `distance` of an obstacle (SensorModel::hitFraction over the
/// group; 0 without a beam).
double hitFraction(const SensorModel& model, const std::vector<PreparedScan>& scans,
                   const Pose2& pose, double distance);

}  // namespace pf

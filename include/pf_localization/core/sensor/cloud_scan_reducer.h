// A 3D point cloud (a spinning 3D lidar, a depth camera) reduced to the
// planar LaserScan the filter already scores, so that a cloud costs about
// what a scan costs and needs no sensor model of its own.
//
// The algorithm, for each point p given in the sensor frame:
//   1. q = R p + t, the point in the base frame (R, t: the sensor's mounting,
//      which may be tilted: the height test needs the base frame's z);
//   2. drop it if any coordinate is NaN or infinite (no return);
//   3. drop it unless min_height <= q.z <= max_height: the floor, the
//      ceiling, things lower than the band (boxes, a pallet) or hanging
//      above it (lamps, a shelf's top) are not what the 2D map shows;
//   4. measure it from the vertical line through the sensor: its horizontal
//      distance d and its bearing about that line, counterclockwise from the
//      sensor's x axis projected onto the floor plane; drop it unless
//      min_range <= d < max_range (the robot's own body; what a 2D scan would
//      not reach);
//   5. put it in the angular bin of its bearing: bin k is centred on
//      -pi + k * w and w = 2 pi / bins wide, bins = ceil(2 pi / bin_width)
//      (the bins close the circle, so the width is bin_width or slightly
//      less); a bin's range is the mean d of its points within
//      kSurfaceDepth (0.1 m) of its nearest: the first obstacle in that
//      direction, as a 2D lidar would see it.
// The scan's sensor_pose is the sensor's place and heading projected onto
// the floor plane (the base frame's heading if the sensor's x axis is
// vertical), so each beam starts where the sensor really is. A bin
// without a point reads NaN, "no reading" (laser_scan.h): the band may
// have removed what was there, so it does not say the direction is free.
//
// (The mean, not the nearest point: the nearest is also the one whose range
// noise is most negative.) The bearing is measured by fastAtan2
// (fast_math.h). See docs/design.md, "A point cloud becomes a scan".
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/util/parameter_table.h"

namespace pf {

/// A point in the sensor's frame (m). NaN or inf in any coordinate: no return.
struct CloudPoint {
  float x, y, z;
};

/// Where the sensor sits on the robot: a point p in the sensor frame is
/// rotation * p + translation in the base frame (the transform base <- sensor,
/// as tf gives it for the base frame and the cloud's frame).
struct SensorMount {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  /// From a translation (m) and roll, pitch, yaw (rad) about the fixed x,
  /// y and z axes, in that order (R = Rz(yaw) Ry(pitch) Rx(roll)), as in
  /// URDF and tf's setRPY.
  static SensorMount fromRpy(double x, double y, double z, double roll, double pitch, double yaw);
};

/// Why a mounting cannot be used: a non-finite entry, or a rotation that is
/// not one (not orthonormal within 1e-6, or a reflection). Empty when usable.
std::optional<std::string> validateMount(const SensorMount& mount);

struct CloudScanParams {
  // Kept points' height in the base frame (m), min < max. The 2D map was
  // drawn by a lidar a few decimetres above the floor, so what it shows are
  // the walls and whatever stands at that height: the band keeps that,
  // above the floor, parcels and pallets, below table tops, wall cabinets
  // and the ceiling (the simulator's building_clutter.h is laid out so).
  double min_height = 0.3;
  double max_height = 0.9;
  // Width of the scan's angular bins (rad); 0.5 deg gives 720 bins, the
  // resolution of a good 2D lidar and well above a 16-ring lidar's 0.2 deg
  // columns, so most bins hold a point. [0.001, pi/4]
  double bin_width = M_PI / 360.0;
  // Horizontal distance from the sensor's vertical axis (m) below which a
  // point is the robot itself (a mast, a bumper). >= 0
  double min_range = 0.2;
  // ... and at or beyond which a point is not used: the scan's range_max. > min_range
  double max_range = 30.0;
};

/// The parameters of CloudScanParams (parameter_table.h): cloud_min_height,
/// cloud_max_height, cloud_bin_width, cloud_min_range, cloud_max_range.
const ParameterTable<CloudScanParams>& cloudScanParameters();

/// Throws std::invalid_argument naming the first value out of range, its
/// value and its valid range.
void validate(const CloudScanParams& params);

/// What became of a cloud's points; every point is counted once, in the first
/// of these tests that drops it (in this order), so that
/// points == not_finite + below_band + above_band + too_near + too_far + kept.
struct CloudScanCounts {
  std::size_t points = 0;       // in the cloud
  std::size_t not_finite = 0;   // NaN or inf: no return
  std::size_t below_band = 0;   // base-frame height < min_height (the floor)
  std::size_t above_band = 0;   // > max_height (the ceiling)
  std::size_t too_near = 0;     // horizontal distance < min_range
  std::size_t too_far = 0;      // >= max_range
  std::size_t kept = 0;         // binned
  std::size_t bins_filled = 0;  // bins with at least one kept point
};

struct CloudScan {
  LaserScan scan;
  CloudScanCounts counts;
};

/// Reduces clouds to scans with fixed parameters (see the top of this file).
class CloudScanReducer {
 public:
  /// Throws std::invalid_argument (see validate()).
  explicit CloudScanReducer(const CloudScanParams& params);

  const CloudScanParams& params() const { return params_; }
  /// The scan's number of beams.
  int bins() const { return bins_; }

  /// The scan of `points` (in the sensor frame) for a sensor mounted at
  /// `mount`. Throws std::invalid_argument if validateMount(mount) fails.
  /// O(points + bins).
  CloudScan reduce(const std::vector<CloudPoint>& points, const SensorMount& mount) const;

 private:
  CloudScanParams params_;
  int bins_;
};

}  // namespace pf

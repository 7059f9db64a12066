// A planar laser scan as the core sees it: ROS-free, with the sensor's pose on
// the robot attached, because the filter needs both to place beam end points.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/motion/scan_deskew.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

struct LaserScan {
  std::vector<float> ranges;     // metres; NaN, inf, 0 and negatives mean "no reading"
  double angle_min = 0.0;        // rad, angle of ranges[0] in the sensor frame
  double angle_increment = 0.0;  // rad between consecutive beams (may be negative)
  double range_min = 0.0;        // m
  double range_max = 0.0;        // m
  Pose2 sensor_pose;             // the laser frame in the robot's base frame
  SweepMotion sweep;             // when each beam was taken (default: all at once)
  // The robot's pose at this scan's stamp in its frame at the update that
  // uses it: the identity, but for the earlier scans of other sensors in a
  // group (scan_group.h), whose beams start where their sensor was then.
  Pose2 robot_offset;
  // How much this sensor's evidence counts: its log-likelihood is multiplied
  // by it. 1, but for a sensor known to be worse than the others. (0, 1]
  double weight = 1.0;
};

/// Why a scan cannot be used at all (as opposed to single bad beams, which are
/// dropped quietly): an empty range array, a zero or non-finite angle
/// increment, non-finite angles, range_max <= range_min, a non-finite
/// sensor pose, robot offset or sweep, or a weight outside (0, 1]. Empty when the scan is usable.
std::optional<std::string> validateScan(const LaserScan& scan);

/// Whether range `r` is a reading within (lo, hi): NaN, inf, zero and
/// negatives are not. A reading of `lo` itself is a driver's "too close to
/// measure" (REP 117's -inf, clamped), not a range.
inline bool isReading(float r, double lo, double hi) { return r > 0.0f && r > lo && r < hi; }

/// One usable beam: its measured range, its bearing in the sensor frame and
/// its index in the scan (which says when it was taken).
struct Beam {
  float range;
  float bearing;
  std::size_t index;
};

/// The usable beams of a scan, evenly subsampled to at most `max_beams`.
///
/// Invalid beams (NaN, inf, <= 0, at or below range_min, at or above range_max) are
/// dropped *before* subsampling: on a Neato a third of the beams can be
/// dropouts, and subsampling first would waste the beam budget on them.
/// `range_min`/`range_max` narrow the scan's own limits when they are tighter
/// (pass a non-positive value to use the scan's). max_beams <= 0 keeps all.
/// `valid_count`, when given, receives the number of valid beams before subsampling.
std::vector<Beam> selectBeams(const LaserScan& scan, int max_beams, double range_min = 0.0,
                              double range_max = 0.0, std::size_t* valid_count = nullptr);

}  // namespace pf

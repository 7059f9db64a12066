// Test support: drive a robot along a known path and let a filter track it
// from odometry and scans, as the node does, then compare with the truth.
#pragma once

#include <vector>

#include "pf_localization/core/filter/particle_filter.h"
#include "support/scan_simulator.h"

namespace pf::test {

/// `start`, then `steps` more poses, each `step` (in the robot's frame) on
/// from the one before: {1, 1.5, 0}, {0.25, 0, 0.05} is a gentle left curve.
std::vector<Pose2> stepPath(const Pose2& start, const Pose2& step, int steps);

/// Appends `steps` more poses to `path` (not empty), each `step` on from the
/// one before: a path of several legs, e.g. ahead, a half turn, and back.
void driveOn(std::vector<Pose2>* path, const Pose2& step, int steps);

/// The odometry that reads `truth` when map -> odom is `odom_in_map`:
/// inverse(odom_in_map) (+) truth.
Pose2 odometryOf(const Pose2& truth, const Pose2& odom_in_map);

/// One step of a drive: the truth, what the filter made of it, and how far off.
struct TrackedStep {
  Pose2 truth;
  Pose2 estimate;
  UpdateReport report;
  double position_error = 0.0;  // m, |estimate - truth| in x, y
  double yaw_error = 0.0;       // rad, |angleDiff(estimate, truth)|
};

struct TrackingRun {
  std::vector<TrackedStep> steps;
  const TrackedStep& last() const { return steps.back(); }
  /// The largest errors from step `from` on (to let the filter converge first).
  double maxPositionError(std::size_t from = 0) const;
  double maxYawError(std::size_t from = 0) const;
  /// The first step from which on every estimate is within both errors of
  /// the truth; -1 when the last one is not.
  int settledAt(double max_position_error, double max_yaw_error) const;
};

/// Drives `path`: at each pose, feeds `filter` the odometry
/// odometryOf(truth, odom_in_map) (so that map -> odom is `odom_in_map`) and
/// the scan `scans` takes from the truth, and records the estimate. The
/// filter must have its map and be initialised.
TrackingRun driveAndTrack(ParticleFilter* filter, const std::vector<Pose2>& path,
                          ScanSimulator* scans, const Pose2& odom_in_map = {});

}  // namespace pf::test

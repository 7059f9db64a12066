#include "support/drive_and_track.h"

#include <algorithm>
#include <cmath>

namespace pf::test {

std::vector<Pose2> stepPath(const Pose2& start, const Pose2& step, int steps) {
  std::vector<Pose2> path{start};
  driveOn(&path, step, steps);
  return path;
}

void driveOn(std::vector<Pose2>* path, const Pose2& step, int steps) {
  for (int k = 0; k < steps; ++k) path->push_back(compose(path->back(), step));
}

Pose2 odometryOf(const Pose2& truth, const Pose2& odom_in_map) {
  return compose(inverse(odom_in_map), truth);
}

double TrackingRun::maxPositionError(std::size_t from) const {
  double worst = 0.0;
  for (std::size_t k = from; k < steps.size(); ++k)
    worst = std::max(worst, steps[k].position_error);
  return worst;
}

double TrackingRun::maxYawError(std::size_t from) const {
  double worst = 0.0;
  for (std::size_t k = from; k < steps.size(); ++k) worst = std::max(worst, steps[k].yaw_error);
  return worst;
}

int TrackingRun::settledAt(double max_position_error, double max_yaw_error) const {
  int settled = -1;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const bool close =
        steps[k].position_error < max_position_error && steps[k].yaw_error < max_yaw_error;
    if (!close) settled = -1;
    if (close && settled < 0) settled = static_cast<int>(k);
  }
  return settled;
}

TrackingRun driveAndTrack(ParticleFilter* filter, const std::vector<Pose2>& path,
                          ScanSimulator* scans, const Pose2& odom_in_map) {
  TrackingRun run;
  run.steps.reserve(path.size());
  for (const Pose2& truth : path) {
    TrackedStep step;
    step.truth = truth;
    step.report = filter->update(odometryOf(truth, odom_in_map), scans->scanFrom(truth));
    step.estimate = filter->estimate().pose;
    step.position_error = std::hypot(step.estimate.x - truth.x, step.estimate.y - truth.y);
    step.yaw_error = std::fabs(angleDiff(step.estimate.yaw, truth.yaw));
    run.steps.push_back(step);
  }
  return run;
}

}  // namespace pf::test

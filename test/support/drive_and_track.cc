#include "support/drive_and_track.h"

#include <algorithm>
#include <cmath>

namespace pf::test {

std::vector<Pose2> stepPath(const Pose2& start, const Pose2& step, int steps) {
  std::vector<Pose2> path{start};
  for (int k = 1; k <= steps; ++k) path.push_back(compose(path.back(), step));
  return path;
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

TrackingRun driveAndTrack(ParticleFilter* filter, const std::vector<Pose2>& path,
                          ScanSimulator* scans, const Pose2& odom_in_map) {
  const Pose2 map_to_odom_inverse = inverse(odom_in_map);
  TrackingRun run;
  run.steps.reserve(path.size());
  for (const Pose2& truth : path) {
    TrackedStep step;
    step.truth = truth;
    step.report = filter->update(compose(map_to_odom_inverse, truth), scans->scanFrom(truth));
    step.estimate = filter->estimate().pose;
    step.position_error = std::hypot(step.estimate.x - truth.x, step.estimate.y - truth.y);
    step.yaw_error = std::fabs(angleDiff(step.estimate.yaw, truth.yaw));
    run.steps.push_back(step);
  }
  return run;
}

}  // namespace pf::test

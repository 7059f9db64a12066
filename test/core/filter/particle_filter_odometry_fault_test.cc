// ParticleFilter when the odometry is wrong: the share of particles given to
// odometry faults rises while the odometry disagrees with the scans (and only
// once a step is long enough to tell), suspect odometry updates on every scan,
// and a scan that stops fitting the predicted pose updates at once.
#include <gtest/gtest.h>

#include <vector>

#include "core/filter/particle_filter_world.h"
#include "pf_localization/core/filter/particle_filter.h"

namespace pf {
namespace {

using filter_world::asymmetricRoom;
using filter_world::exactParams;
using filter_world::simulateScan;

// Where the odometry fault and fit tests start, every particle there.
const Pose2 kAtRest{1.5, 1.5, 0.0};

// Gives `filter` the map `grid`, puts every particle at kAtRest and updates
// on the scan taken there, with the odometry at its origin.
UpdateReport firstUpdateAtRest(ParticleFilter* filter, const OccupancyGrid& grid) {
  filter->setMap(grid);
  filter->initializeGaussian(kAtRest, Eigen::Matrix3d::Zero());
  return filter->update({0.0, 0.0, 0.0}, simulateScan(grid, kAtRest));
}

// exactParams with 1000 particles, of which odometry faults get 0.02 to 0.5.
ParticleFilterParams faultParams() {
  ParticleFilterParams params = exactParams();
  params.kld.min_particles = params.kld.max_particles = 1000;
  params.motion.fault_fraction = 0.02;
  params.motion.fault_fraction_max = 0.5;
  return params;
}

// The share of particles the filter gives to odometry faults after each of
// `steps` updates in which the odometry reports 0.3 m forwards along x and the
// scans are taken at `truth_step` metres per update from kAtRest.
std::vector<double> faultShares(double truth_step, int steps, double odom_step = 0.3) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = faultParams();
  params.update_min_d = 0.0;  // every step updates, however short
  params.motion.fault_margin = 0.05;
  ParticleFilter filter(params);
  firstUpdateAtRest(&filter, grid);
  std::vector<double> shares;
  for (int k = 1; k <= steps; ++k) {
    const Pose2 truth{kAtRest.x + truth_step * k, kAtRest.y, 0.0};
    const UpdateReport r = filter.update({odom_step * k, 0.0, 0.0}, simulateScan(grid, truth));
    EXPECT_TRUE(r.updated) << skipMessage(r);
    shares.push_back(r.fault_fraction);
  }
  return shares;
}

TEST(ParticleFilterUpdate, StepsTooShortToShowAFaultLeaveTheFaultShareAlone) {
  // 0.02 m steps reversed: twice that is below the 0.05 m margin within
  // which stalled particles spread anyway, so the scans cannot tell and the
  // share stays at the floor (it would climb to the maximum otherwise).
  for (double share : faultShares(-0.02, 4, 0.02)) EXPECT_DOUBLE_EQ(0.02, share);
  // 0.03 m steps reversed are 0.06 m off: observable, and the share rises.
  EXPECT_GT(faultShares(-0.03, 4, 0.03).back(), 0.02);
}

TEST(ParticleFilterUpdate, TheFaultShareRisesWhileTheOdometryIsReversedAndFallsBack) {
  // Right odometry: the faulty particles win nothing, the share stays at the floor.
  for (double share : faultShares(0.3, 3)) EXPECT_DOUBLE_EQ(0.02, share);
  // Odometry that reports forwards while the robot reverses: the reversed
  // particles win the weight, and the next step gives faults the maximum.
  const std::vector<double> reversed = faultShares(-0.3, 3);
  for (double share : reversed) EXPECT_DOUBLE_EQ(0.5, share);
}

// Whether the filter updates on a 0.3 m step below update_min_d (1 m),
// after one forced update on which the robot moved `truth_step` while the
// odometry said 0.3 m forwards.
bool updatesOnAShortStepAfter(double truth_step) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = faultParams();
  params.update_min_d = 1.0;
  params.update_min_a = 1.0;
  params.motion.fault_suspect_fraction = 0.1;
  ParticleFilter filter(params);
  firstUpdateAtRest(&filter, grid);
  filter.requestNoMotionUpdate();
  const Pose2 truth{kAtRest.x + truth_step, kAtRest.y, 0.0};
  EXPECT_TRUE(filter.update({0.3, 0.0, 0.0}, simulateScan(grid, truth)).updated);
  const UpdateReport next =
      filter.update({0.6, 0.0, 0.0}, simulateScan(grid, {truth.x + truth_step, truth.y, 0.0}));
  return next.updated;
}

TEST(ParticleFilterUpdate, SuspectOdometryUpdatesOnEveryScan) {
  // Right odometry: the next 0.3 m waits for update_min_d as usual.
  EXPECT_FALSE(updatesOnAShortStepAfter(0.3));
  // Reversed: the faulty particles won (share 0.5 >= 0.1), so the odometry
  // between updates is not trusted and the next scan updates at once.
  EXPECT_TRUE(updatesOnAShortStepAfter(-0.3));
}

// Whether the filter updates on a scan taken after the robot moved
// `truth_step` m forward while the odometry counted 0.15 m (below
// update_min_d 0.2 m).
UpdateReport shortStepUpdate(double truth_step, double fit_drop) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = exactParams();
  params.update_fit_drop = fit_drop;
  params.update_fit_distance = 0.1;
  ParticleFilter filter(params);
  EXPECT_TRUE(firstUpdateAtRest(&filter, grid).updated);
  return filter.update({0.15, 0.0, 0.0},
                       simulateScan(grid, {kAtRest.x + truth_step, kAtRest.y, 0.0}));
}

TEST(ParticleFilterUpdate, AScanThatStopsFittingThePredictedPoseUpdatesAtOnce) {
  // The odometry was right: the scan fits where it says, so the filter waits
  // for update_min_d.
  UpdateReport r = shortStepUpdate(0.15, 0.25);
  EXPECT_FALSE(r.updated);
  EXPECT_FALSE(r.fit_dropped);
  // The robot reversed while the encoders counted forwards: at the predicted
  // pose, 0.3 m from the truth, most beams miss the walls by more than 0.1 m.
  r = shortStepUpdate(-0.15, 0.25);
  EXPECT_TRUE(r.updated) << skipMessage(r);
  EXPECT_TRUE(r.fit_dropped);
  // The robot stalled: 0.15 m off, still a clear drop.
  EXPECT_TRUE(shortStepUpdate(0.0, 0.25).fit_dropped);
  // A drop of 1 can never happen: the check is off in effect, as with 0.
  EXPECT_FALSE(shortStepUpdate(-0.15, 1.0).updated);
  EXPECT_FALSE(shortStepUpdate(-0.15, 0.0).updated);
}

}  // namespace
}  // namespace pf

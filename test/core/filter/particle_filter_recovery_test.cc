// ParticleFilter's recovery from a robot carried away unseen: expansion
// resetting spreads a cloud whose fit collapsed, random particles are injected
// only into free space, at once for a compact cloud that is lost, weighted by
// the kidnap prior, not tempered away, and only after the patience of a filter
// that is not lost.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/filter/particle_filter_world.h"
#include "pf_localization/core/filter/particle_filter.h"

namespace pf {
namespace {

using filter_world::asymmetricRoom;
using filter_world::diag;
using filter_world::exactParams;
using filter_world::kRes;
using filter_world::simulateScan;

// exactParams with 500 particles, an update on every scan and augmented
// MCL's averages on (expansion resetting stays off): for the recovery tests.
ParticleFilterParams recoveryParams() {
  ParticleFilterParams p = exactParams();
  p.kld.min_particles = p.kld.max_particles = 500;
  p.recovery.alpha_slow = 0.01;
  p.recovery.alpha_fast = 0.2;
  p.update_min_d = p.update_min_a = 0.0;
  return p;
}

// An update on `scan` with the odometry at rest that counts a whole new view
// (view_share.h), as the recovery tests' robot is carried without odometry:
// a requested update (amcl's request_nomotion_update) does. Without the
// request, a scan taken where the odometry has not moved brings no new view.
UpdateReport viewUpdate(ParticleFilter* filter, const LaserScan& scan) {
  filter->requestNoMotionUpdate();
  return filter->update({0.0, 0.0, 0.0}, scan);
}

// The recovery tests' robot: tracked at kTracked for five scans, then moved
// to kMoved (1.3 m away and turned) without the odometry seeing it.
const Pose2 kTracked{1.0, 1.5, 0.2};
const Pose2 kMoved{2.0, 2.2, 1.5};

void trackFiveScans(const OccupancyGrid& grid, ParticleFilter* filter,
                    const Eigen::Matrix3d& start_cov = Eigen::Matrix3d::Zero()) {
  filter->setMap(grid);
  filter->initializeGaussian(kTracked, start_cov);
  const LaserScan good = simulateScan(grid, kTracked);
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(viewUpdate(filter, good).updated);
}

// Feeds scans taken at kMoved until recovery injects (five at most).
UpdateReport updateUntilInjection(const OccupancyGrid& grid, ParticleFilter* filter) {
  UpdateReport r;
  for (int k = 0; k < 5 && r.injected == 0; ++k) {
    r = viewUpdate(filter, simulateScan(grid, kMoved));
  }
  return r;
}

TEST(ParticleFilterUpdate, ACollapsedFitSpreadsTheSurvivors) {
  // Expansion resetting: tracking well at `start`, then the robot is pushed
  // 0.5 m sideways without odometry seeing it. That scan fits far worse than
  // usual, and the resampled particles are spread to search nearby.
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.recovery.expansion_ratio = 0.3;
  params.recovery.expansion_std_xy = 0.3;
  ParticleFilter filter(params);
  filter.setMap(grid);
  const Pose2 start{1.0, 1.5, 0.2};
  filter.initializeGaussian(start, Eigen::Matrix3d::Zero());
  const LaserScan scan = simulateScan(grid, start);
  for (int k = 0; k < 3; ++k) {
    const UpdateReport r = viewUpdate(&filter, scan);
    ASSERT_TRUE(r.updated);
    EXPECT_FALSE(r.expanded) << "update " << k;
  }
  const UpdateReport pushed = viewUpdate(&filter, simulateScan(grid, {1.0, 2.0, 0.2}));
  ASSERT_TRUE(pushed.updated);
  EXPECT_TRUE(pushed.expanded);
  double spread = 0.0;
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    spread = std::max(
        spread, std::hypot(filter.particles().x[i] - start.x, filter.particles().y[i] - start.y));
  }
  EXPECT_GT(spread, 0.5);  // all particles sat exactly at `start` before
}

// Tracks at `start` on `grid`, then feeds scans taken 1 m away that fit far
// worse than the usual ones; returns the random particles recovery injected.
std::size_t injectedAfterScansStopFitting(const OccupancyGrid& grid) {
  // The scans are simulated on the mapped room, whatever `grid` is.
  ParticleFilter filter(recoveryParams());
  filter.setMap(grid);
  filter.initializeGaussian(kTracked, Eigen::Matrix3d::Zero());
  const LaserScan good = simulateScan(asymmetricRoom(), kTracked);
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(viewUpdate(&filter, good).updated);
  const LaserScan moved = simulateScan(asymmetricRoom(), kMoved);
  std::size_t injected = 0;
  for (int k = 0; k < 5; ++k) {
    const UpdateReport r = viewUpdate(&filter, moved);
    EXPECT_TRUE(r.updated) << skipMessage(r);
    injected += r.injected;
  }
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    EXPECT_TRUE(filter.particles().pose(i).isFinite());
  }
  EXPECT_TRUE(filter.estimate().pose.isFinite());
  return injected;
}

TEST(ParticleFilterUpdate, RecoveryInjectsOnlyWhereThereIsFreeSpace) {
  // The same room and scans, once as mapped and once with every free cell
  // unknown (found by fuzz_core: drawing from an empty free-cell list).
  const OccupancyGrid mapped = asymmetricRoom();
  std::vector<int8_t> data(mapped.data());
  for (int8_t& v : data) v = v == 0 ? -1 : v;
  const OccupancyGrid no_free(mapped.width(), mapped.height(), kRes, {}, data);
  ASSERT_TRUE(no_free.freeCells().empty());
  EXPECT_GT(injectedAfterScansStopFitting(mapped), 0u);
  EXPECT_EQ(injectedAfterScansStopFitting(no_free), 0u);
}

// The random particles injected on the first scan after the robot was
// carried from kTracked to kMoved, for a filter of at least 500 and at most
// `max_particles` particles and the given lost_share.
std::size_t injectedOnTheFirstLostScan(std::size_t max_particles, double lost_share) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.kld.max_particles = static_cast<int>(max_particles);
  params.recovery.lost_share = lost_share;
  params.resample_ess_fraction = 1.0;  // resample at every update: KLD shrinks the cloud
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter, diag(0.01, 0.01, 0.01));  // spread: the weights differ
  // Compact (569 particles, one bin or two) for a budget of 2000; not for one of 800.
  EXPECT_EQ(max_particles >= 2000, filter.particles().size() <= max_particles / 2);
  const UpdateReport r = filter.update({0.0, 0.0, 0.0}, simulateScan(grid, kMoved));
  EXPECT_TRUE(r.updated);
  EXPECT_EQ(LocalizationState::kLost, filter.confidence().state);
  return r.injected;
}

TEST(ParticleFilterUpdate, ACompactCloudThatIsLostSearchesAtOnceWithItsShareOfTheBudget) {
  // 500 particles of a budget of 2000 (compact): lost_share of the budget
  // is drawn on the very scan that finds the robot elsewhere. Without the
  // floor, the slow averages inject nothing until the second bad scan.
  EXPECT_EQ(1000u, injectedOnTheFirstLostScan(2000, 0.5));
  EXPECT_EQ(600u, injectedOnTheFirstLostScan(2000, 0.3));
  EXPECT_EQ(0u, injectedOnTheFirstLostScan(2000, 0.0));
  // 666 particles of a budget of 800 are more than (1 - 0.5) of it: a
  // cloud that is already searching is not thinned.
  EXPECT_EQ(0u, injectedOnTheFirstLostScan(800, 0.5));
}

TEST(ParticleFilterUpdate, InjectedParticlesWeighTheKidnapPriorTogether) {
  // Mixture-proposal weights: whatever their number, the random particles
  // hold kidnap_prior of the weight and the survivors the rest.
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.recovery.kidnap_prior = 0.01;
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter);
  const UpdateReport r = updateUntilInjection(grid, &filter);
  ASSERT_GT(r.injected, 0u);
  const ParticleSet& p = filter.particles();
  const std::size_t kept = p.size() - r.injected;
  double w_kept = 0.0, w_injected = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) (i < kept ? w_kept : w_injected) += p.weight[i];
  EXPECT_NEAR(0.99, w_kept, 1e-12);
  EXPECT_NEAR(0.01, w_injected, 1e-12);
  EXPECT_DOUBLE_EQ(0.01 / static_cast<double>(r.injected), p.weight.back());
}

TEST(ParticleFilterUpdate, RecoveryGuessesDoNotTemperTheNextScanAway) {
  // After an injection some particles are barely weighted guesses, so the
  // weights' effective sample size is below N. Tempering keeps a share of
  // that ESS; measured against N instead, a share above ESS / N could never
  // be kept, and every scan was tempered to an exponent of 0: ignored.
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.tempering_ess_fraction = params.tempering_ess_fraction_uncertain = 0.99;
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter);
  ASSERT_GT(updateUntilInjection(grid, &filter).injected, 0u);
  const double prior_ess = effectiveSampleSize(filter.particles().weight);
  ASSERT_LT(prior_ess, 0.99 * static_cast<double>(filter.particles().size()));
  const UpdateReport next = viewUpdate(&filter, simulateScan(grid, kMoved));
  ASSERT_TRUE(next.updated);
  EXPECT_GT(next.tempering, 0.0);
  EXPECT_LT(next.tempering, 1.0);
  EXPECT_NEAR(0.99 * prior_ess, next.ess, 0.01 * prior_ess);  // the bisection's target
}

// The number of updates with bad scans before recovery injects (-1: none in
// 30), for a filter whose thresholds keep it in `state` whatever the fit
// (as it judges the fit; the published state of a "localized" one turns
// "uncertain" once the dip has lasted more than `patience` updates, or
// while a look-alike place fits as well).
int updatesBeforeInjection(int patience, LocalizationState state = LocalizationState::kUncertain,
                           int patience_localized = 10) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = recoveryParams();
  params.recovery.patience = patience;
  params.recovery.patience_localized = patience_localized;
  params.confidence.lost_hit_fraction = params.confidence.localized_hit_fraction = 0.0;
  // Uncertain: no cloud is ever compact enough. Localized: every cloud is.
  const double std_limit = state == LocalizationState::kLocalized ? 100.0 : 1e-9;
  params.confidence.localized_std_xy = params.confidence.localized_std_yaw = std_limit;
  ParticleFilter filter(params);
  trackFiveScans(grid, &filter);
  for (int k = 1; k <= 30; ++k) {
    const UpdateReport r = viewUpdate(&filter, simulateScan(grid, kMoved));
    // The dip starts at the second bad scan: k - 1 updates of low fit. The
    // room's walls also fit a half turn of the wrong estimate about as badly
    // as the estimate, and a look-alike as good holds the verdict too.
    const bool doubted =
        state == LocalizationState::kLocalized && (k - 1 > patience || r.look_alikes > 0);
    EXPECT_EQ(doubted ? LocalizationState::kUncertain : state, filter.confidence().state) << k;
    if (r.injected > 0) return k;
  }
  return -1;
}

TEST(ParticleFilterUpdate, AFilterThatIsNotLostWaitsOutShortDipsBeforeInjecting) {
  // The short-term fit (alpha_fast 0.2) falls below 0.7 of the long-term one
  // at the second bad scan: without patience that update injects; with it,
  // `patience` updates later.
  EXPECT_EQ(2, updatesBeforeInjection(0));
  EXPECT_EQ(5, updatesBeforeInjection(3));
  EXPECT_EQ(12, updatesBeforeInjection(10));
}

TEST(ParticleFilterUpdate, AFilterThatIsLocalizedWaitsLongerBeforeInjecting) {
  // The same dip, while the estimate's beams fit the map and the cloud is
  // compact: more likely a poor map there than a kidnapping (fr079 jumped
  // 28 m from random particles injected while 87 % of the beams fitted), so
  // patience_localized applies; but a dip that lasts is still searched.
  EXPECT_EQ(22, updatesBeforeInjection(0, LocalizationState::kLocalized, 20));
  EXPECT_EQ(22, updatesBeforeInjection(3, LocalizationState::kLocalized, 20));
  EXPECT_EQ(5, updatesBeforeInjection(3, LocalizationState::kLocalized, 3));
}

}  // namespace
}  // namespace pf

// LookAlikes: the map's symmetries (shifts between twin rooms, the half turn
// of a bare hall, none in a scatter of obstacles), what a scan says of them,
// and a filter carried into a twin room finding itself there.
#include "pf_localization/core/recovery/look_alikes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/recovery/recovery.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/util/random.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

// Two closed 4 m x 3 m rooms side by side, furnished alike (x 0-4 and 4-8),
// and a cabinet in the upper right of the east room only: from most of
// either room, with a 2 m lidar, the rooms look the same.
OccupancyGrid twinRooms() {
  return test::room(8.0, 3.0, 0.05,
                    {{3.95, 0.0, 4.05, 3.0},  // the wall between them
                     {1.0, 0.5, 1.5, 1.0},    // alike in both
                     {5.0, 0.5, 5.5, 1.0},
                     {0.3, 2.0, 0.8, 2.5},
                     {4.3, 2.0, 4.8, 2.5},
                     {6.8, 2.2, 7.4, 2.6}});  // the east room's cabinet
}
const Pose2 kEastShift{4.0, 0.0, 0.0};

test::ScanSpec shortLidar() {
  test::ScanSpec spec;
  spec.range_max = 2.0;
  return spec;
}

bool hasMotion(const std::vector<MapSymmetry>& symmetries, const Pose2& motion, double tol) {
  for (const MapSymmetry& s : symmetries) {
    if (std::hypot(s.motion.x - motion.x, s.motion.y - motion.y) <= tol &&
        std::abs(angleDiff(s.motion.yaw, motion.yaw)) < 1e-6) {
      return true;
    }
  }
  return false;
}

TEST(FindMapSymmetries, FindsTheShiftBetweenTwinRoomsBothWays) {
  const OccupancyGrid grid = twinRooms();
  const DistanceField field(grid, 2.0);
  const std::vector<MapSymmetry> s = findMapSymmetries(field);
  EXPECT_TRUE(hasMotion(s, kEastShift, 0.051));
  EXPECT_TRUE(hasMotion(s, inverse(kEastShift), 0.051));
  for (const MapSymmetry& m : s) {
    EXPECT_GE(m.overlap, LookAlikes::kMinSymmetryOverlap);
    EXPECT_GE(std::hypot(m.motion.x, m.motion.y) + std::abs(m.motion.yaw), LookAlikes::kMinShift);
  }
}

TEST(FindMapSymmetries, FindsTheHalfTurnOfABareHallAboutItsCentre) {
  // A hall of 80 x 60 cells: the half turn about (2, 1.5) maps it onto itself.
  const OccupancyGrid grid = test::room(4.0, 3.0, 0.05);
  const std::vector<MapSymmetry> s = findMapSymmetries(DistanceField(grid, 2.0));
  EXPECT_TRUE(hasMotion(s, {4.0, 3.0, M_PI}, 0.051));
}

TEST(FindMapSymmetries, FindsNoneInAScatterOfObstacles) {
  std::vector<int8_t> data(120 * 90, 0);
  Random random(3);
  for (int k = 0; k < 300; ++k)
    data[static_cast<std::size_t>(random.uniform() * data.size())] = 100;
  const OccupancyGrid grid(120, 90, 0.05, {}, data);
  EXPECT_TRUE(findMapSymmetries(DistanceField(grid, 2.0)).empty());
}

TEST(FindMapSymmetries, GivesWorldMotionsOnAGridWithAnOrigin) {
  const Pose2 origin{-3.0, 5.0, 0.5};
  const OccupancyGrid rotated = test::room(4.0, 3.0, 0.05, {}, origin);
  const std::vector<MapSymmetry> s = findMapSymmetries(DistanceField(rotated, 2.0));
  // The hall's centre, in the world, is a fixed point of its half turn.
  double cx = 0.0, cy = 0.0;
  rotated.cellToWorld({40, 30}, &cx, &cy);
  const Pose2 centre{cx - 0.025 * (std::cos(0.5) - std::sin(0.5)),
                     cy - 0.025 * (std::sin(0.5) + std::cos(0.5)), 0.0};
  bool fixed = false;
  for (const MapSymmetry& m : s) {
    const Pose2 c = compose(m.motion, centre);
    fixed = fixed || (std::hypot(c.x - centre.x, c.y - centre.y) < 0.06 &&
                      std::abs(angleDiff(m.motion.yaw, M_PI)) < 1e-6);
  }
  EXPECT_TRUE(fixed);
}

class LookAlikesInTwinRooms : public ::testing::Test {
 protected:
  LookAlikesInTwinRooms() : grid_(twinRooms()), model_(grid_, LikelihoodFieldModelParams{}) {
    look_alikes_.setMap(model_.field());
  }
  std::vector<PreparedScan> scanFrom(const Pose2& pose) {
    return {model_.prepare(test::simulateScan(grid_, pose, shortLidar()))};
  }

  OccupancyGrid grid_;
  LikelihoodFieldModel model_;
  LookAlikes look_alikes_;
};

TEST_F(LookAlikesInTwinRooms, AScanThatCannotTellTheRoomsApartFitsTheTwinAsWell) {
  const Pose2 west{2.0, 1.5, 0.3};
  const LookAlikeView view = look_alikes_.judge(model_, scanFrom(west), west);
  EXPECT_GE(view.as_good, 1u);
  EXPECT_TRUE(view.better.empty());
  EXPECT_NEAR(view.fit, view.best_fit, LookAlikes::kAsGoodMargin);
  ASSERT_EQ(view.as_good, view.places.size());
  const Pose2 twin = compose(kEastShift, west);
  bool listed = false;
  for (const LookAlikePlace& p : view.places)
    listed = listed || std::hypot(p.pose.x - twin.x, p.pose.y - twin.y) < 0.06;
  EXPECT_TRUE(listed);
}

TEST(AddLookAlikes, ListsThePlacesTheCloudDoesNotHoldWithNoWeight) {
  Hypotheses h;
  h.count = 1;
  h.listed.push_back({{2.0, 1.5, 0.3}, 1.0, Eigen::Vector3d(0.01, 0.02, 0.001).asDiagonal(), 800});
  // One look-alike the cloud holds already (within kMinShift), one it does not.
  addLookAlikes({{{2.5, 1.5, 0.3}, 1.0}, {{6.0, 1.5, 0.3}, 1.0}}, &h);
  EXPECT_EQ(2u, h.count);
  ASSERT_EQ(2u, h.listed.size());
  EXPECT_DOUBLE_EQ(6.0, h.listed[1].pose.x);
  EXPECT_EQ(0.0, h.listed[1].weight);
  EXPECT_EQ(0u, h.listed[1].particles);
  EXPECT_TRUE(h.listed[1].covariance.isApprox(h.listed[0].covariance));
  // Without a hypothesis of the cloud there is nothing to be like.
  Hypotheses none;
  addLookAlikes({{{6.0, 1.5, 0.3}, 1.0}}, &none);
  EXPECT_EQ(0u, none.count);
}

TEST(AddLookAlikes, ListsTheBestFittingFirstAndEachPlaceOnce) {
  Hypotheses h;
  h.count = 1;
  h.listed.push_back({{2.0, 1.5, 0.3}, 1.0, Eigen::Vector3d(0.01, 0.02, 0.001).asDiagonal(), 800});
  // Two look-alikes of one place reached from two held places (0.3 m
  // apart, the same place), and a worse fitting one elsewhere.
  addLookAlikes({{{6.0, 1.5, 0.3}, -5.0}, {{10.3, 1.5, 0.3}, 1.0}, {{10.0, 1.5, 0.3}, 2.0}}, &h);
  EXPECT_EQ(3u, h.count);
  ASSERT_EQ(3u, h.listed.size());
  EXPECT_DOUBLE_EQ(10.0, h.listed[1].pose.x);
  EXPECT_DOUBLE_EQ(6.0, h.listed[2].pose.x);
}

TEST_F(LookAlikesInTwinRooms, APlaceTheCloudHoldsNamesItsTwinWhereTheScanFits) {
  // The scan is taken in the west room; the cloud holds, besides its
  // estimate, a place in the east room. Its look-alike is the true pose.
  const Pose2 west{2.0, 1.5, 0.3};
  const std::vector<PreparedScan> scans = scanFrom(west);
  const double fit = look_alikes_.judge(model_, scans, west).fit;
  const Pose2 east = compose(kEastShift, west);
  const std::vector<LookAlikePlace> around =
      look_alikes_.placesAround(model_, scans, {east}, fit - LookAlikes::kAsGoodMargin);
  const auto truth = std::find_if(around.begin(), around.end(), [&](const LookAlikePlace& p) {
    return std::hypot(p.pose.x - west.x, p.pose.y - west.y) < 0.06;
  });
  ASSERT_NE(around.end(), truth);
  EXPECT_NEAR(fit, truth->fit, LookAlikes::kAsGoodMargin);
  // Where the scan fits worse than asked for, nothing is named.
  for (const LookAlikePlace& p : look_alikes_.placesAround(model_, scans, {east}, truth->fit + 1.0))
    EXPECT_GT(std::hypot(p.pose.x - west.x, p.pose.y - west.y), 0.06);
  // A cloud holding no other place has no look-alikes to name.
  EXPECT_TRUE(look_alikes_.placesAround(model_, scans, {}, -1e9).empty());
}

TEST_F(LookAlikesInTwinRooms, TheCabinetTellsThemApart) {
  // In the east room, by the cabinet: the west twin fits worse.
  const Pose2 east{6.6, 1.9, 0.3};
  const LookAlikeView view = look_alikes_.judge(model_, scanFrom(east), east);
  EXPECT_EQ(0u, view.as_good);
  EXPECT_TRUE(view.better.empty());
  EXPECT_LT(view.best_fit, view.fit - LookAlikes::kBetterMargin);
}

TEST_F(LookAlikesInTwinRooms, ATwinThatFitsClearlyBetterCountsAfterItsStreak) {
  // The robot is by the cabinet; the estimate is the same place in the west room.
  const Pose2 east{6.6, 1.9, 0.3};
  const Pose2 wrong = compose(inverse(kEastShift), east);
  const std::vector<PreparedScan> scan = scanFrom(east);
  for (int k = 1; k <= LookAlikes::kBetterUpdates; ++k) {
    const LookAlikeView view = look_alikes_.judge(model_, scan, wrong);
    if (k < LookAlikes::kBetterUpdates) {
      EXPECT_TRUE(view.better.empty()) << k;
      continue;
    }
    ASSERT_EQ(1u, view.better.size());
    EXPECT_NEAR(kEastShift.x, view.better[0].x, 0.051);
    EXPECT_NEAR(kEastShift.y, view.better[0].y, 0.051);
  }
  // A scan that cannot tell them apart breaks the streak.
  const Pose2 west{2.0, 1.5, 0.3};
  look_alikes_.judge(model_, scanFrom(west), west);
  EXPECT_TRUE(look_alikes_.judge(model_, scan, wrong).better.empty());
}

TEST(LookAlikeMove, CopiesTheSurvivorsToEachBetterLookAlikeHoweverTheScansFit) {
  RecoveryContext context;
  context.slow = 1.0;
  context.fast = 0.9;  // above trigger_ratio (0.7) of the usual fit
  context.better_look_alikes = {kEastShift};
  RecoveryParams params;
  RecoveryPlan plan;
  LookAlikeMove strategy;
  strategy.contribute(context, params, &plan);
  ASSERT_EQ(1u, plan.moves.size());
  context.better_look_alikes.clear();
  plan = RecoveryPlan();
  strategy.contribute(context, params, &plan);
  EXPECT_TRUE(plan.moves.empty());

  const auto cloud = [](std::size_t n) {
    ParticleSet particles;
    particles.resize(n);
    for (std::size_t i = 0; i < n; ++i) particles.setPose(i, {1.0, 0.01 * i, 0.2});
    return particles;
  };
  // Room for all: the tracked place keeps its 100, the look-alike gets 100 more.
  ParticleSet particles = cloud(100);
  EXPECT_EQ(100u, LookAlikeMove::copy({kEastShift}, 100, 1000, &particles));
  ASSERT_EQ(200u, particles.size());
  EXPECT_DOUBLE_EQ(1.0, particles.x[0]);
  EXPECT_DOUBLE_EQ(0.01, particles.y[1]);
  EXPECT_DOUBLE_EQ(5.0, particles.x[101]);
  EXPECT_DOUBLE_EQ(0.01, particles.y[101]);
  EXPECT_DOUBLE_EQ(0.2, particles.yaw[101]);
  // Room for 160: three look-alikes take 20 each, every fifth survivor.
  particles = cloud(100);
  EXPECT_EQ(60u, LookAlikeMove::copy({kEastShift, kEastShift, kEastShift}, 100, 160, &particles));
  ASSERT_EQ(160u, particles.size());
  EXPECT_DOUBLE_EQ(5.0, particles.x[159]);
  EXPECT_DOUBLE_EQ(0.95, particles.y[159]);
  // No room beyond the survivors, or no look-alike: nothing is added.
  particles = cloud(100);
  EXPECT_EQ(0u, LookAlikeMove::copy({kEastShift}, 100, 100, &particles));
  EXPECT_EQ(0u, LookAlikeMove::copy({}, 100, 1000, &particles));
  EXPECT_EQ(100u, particles.size());
}

TEST(LookAlikes, AFilterCarriedIntoTheTwinRoomDoubtsAndThenFindsItselfThere) {
  const OccupancyGrid grid = twinRooms();
  ParticleFilterParams params;
  params.kld.min_particles = 500;
  params.kld.max_particles = 3000;
  params.update_min_d = 0.02;
  params.seed = 2;
  ParticleFilter filter(params);
  filter.setMap(grid);
  test::ScanSimulator lidar(grid, [] {
    test::ScanSpec spec = shortLidar();
    spec.noise_sigma = 0.01;
    return spec;
  }());
  Pose2 truth{1.8, 1.5, 0.0};
  filter.initializeGaussian(truth, Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal());
  Pose2 odom{0.0, 0.0, 0.0};
  const auto drive = [&](double step) {
    truth = compose(truth, {step, 0.0, 0.0});
    odom = compose(odom, {step, 0.0, 0.0});
    return filter.update(odom, lidar.scanFrom(truth));
  };
  for (int k = 0; k < 5; ++k) drive(0.1);
  // Tracked in the west room, where a twin fits as well: not "localized",
  // and the twin is listed among the hypotheses.
  EXPECT_NE(LocalizationState::kLocalized, filter.confidence().state);
  const Hypotheses h = filter.hypotheses();
  ASSERT_GE(h.listed.size(), 2u);
  EXPECT_NEAR(truth.x + kEastShift.x, h.listed.back().pose.x, 0.1);
  EXPECT_LT(std::hypot(filter.estimate().pose.x - truth.x, filter.estimate().pose.y - truth.y),
            0.1);
  // Carried to the same place in the east room; the odometry does not see it.
  truth = compose(kEastShift, truth);
  // The cabinet is in view: the scan fits the twin better at once, and
  // within 1.2 m of driving east the filter is sure of the east room. On
  // the way it never says "localized" in the west one.
  int found_at = -1;
  for (int k = 0; k < 40 && found_at < 0; ++k) {
    drive(0.03);
    const double error =
        std::hypot(filter.estimate().pose.x - truth.x, filter.estimate().pose.y - truth.y);
    const bool localized = filter.confidence().state == LocalizationState::kLocalized;
    EXPECT_FALSE(localized && error > 0.5) << k;
    if (localized && error < 0.1) found_at = k;
  }
  EXPECT_GE(found_at, 0) << "still off at " << filter.estimate().pose.x << ", "
                         << filter.estimate().pose.y;
}

}  // namespace
}  // namespace pf

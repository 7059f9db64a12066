// ParticleFilter::setMap on a filter that has particles: they stay while the
// estimate is still on free space of the new map, and are dropped otherwise.
#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>
#include <vector>

#include "core/filter/particle_filter_world.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"

namespace pf {
namespace {

using filter_world::asymmetricRoom;
using filter_world::baseParams;
using filter_world::diag;
using filter_world::distance;
using filter_world::odomOf;
using filter_world::room;
using filter_world::simulateScan;

// --- Map changes -------------------------------------------------------------------

TEST(ParticleFilter, ANewMapsTableIsBuiltWithItNotByTheNextUpdate) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = baseParams();
  params.sensor.range_max = 4.0;  // laser_max_range, tighter than the laser's
  ParticleFilter filter(params);
  filter.expectScanRange(8.0);  // a scan seen before the map: scored at 4 m
  filter.setMap(grid);
  const auto& model = dynamic_cast<const LikelihoodFieldModel&>(*filter.sensorModel());
  EXPECT_EQ(1u, model.tablesBuilt());
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.05, 0.05, 0.05));
  LaserScan scan = simulateScan(grid, {1.0, 1.5, 0.0});
  scan.range_max = 8.0;
  ASSERT_TRUE(filter.update(odomOf({1.0, 1.5, 0.0}), scan).updated);
  EXPECT_EQ(1u, model.tablesBuilt());
  // A replaced map's model has the table of the scans weighed before it.
  filter.setMap(room(4.0, 3.0, {{2.5, 0.5, 3.0, 1.2}}));
  EXPECT_EQ(1u, dynamic_cast<const LikelihoodFieldModel&>(*filter.sensorModel()).tablesBuilt());
}

TEST(ParticleFilter, SetMapKeepsParticlesWhenTheEstimateIsStillFree) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.05, 0.05, 0.05));
  ASSERT_TRUE(filter.update(odomOf({1.0, 1.5, 0.0}), simulateScan(grid, {1.0, 1.5, 0.0})).updated);
  const ParticleSet before = filter.particles();

  // The same room with an extra box elsewhere: particles stay.
  EXPECT_TRUE(filter.setMap(room(4.0, 3.0, {{2.5, 0.5, 3.0, 1.2}, {3.0, 2.0, 3.5, 2.5}})));
  EXPECT_TRUE(filter.isInitialized());
  EXPECT_EQ(before.x, filter.particles().x);
  EXPECT_EQ(before.yaw, filter.particles().yaw);
  EXPECT_TRUE(filter.mapToOdom().has_value());

  // A map with a box over the estimate: the particles are dropped.
  EXPECT_FALSE(filter.setMap(room(4.0, 3.0, {{0.5, 1.0, 1.5, 2.0}})));
  EXPECT_FALSE(filter.isInitialized());
  EXPECT_TRUE(filter.particles().empty());
  EXPECT_TRUE(filter.estimate().clusters.empty());
  EXPECT_FALSE(filter.mapToOdom().has_value());
  const UpdateReport r = filter.update(odomOf({1.0, 1.5, 0.0}), simulateScan(grid, {1, 1.5, 0}));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNotInitialized, r.skip_reason) << skipMessage(r);
}

TEST(ParticleFilter, SetMapDropsParticlesWhenTheEstimateLeavesTheMap) {
  ParticleFilter filter(baseParams());
  filter.setMap(asymmetricRoom());
  filter.initializeGaussian({3.5, 2.5, 0.0}, diag(0.05, 0.05, 0.05));
  EXPECT_FALSE(filter.setMap(room(2.0, 2.0, {})));  // (3.5, 2.5) is outside
  EXPECT_FALSE(filter.isInitialized());
  EXPECT_THROW(filter.setMap(OccupancyGrid()), std::invalid_argument);
}

// A node builds a new map while updates run on the current one
// (prepared_map.h), then swaps it in: the filter then runs as if the map had
// been set directly.
TEST(ParticleFilter, AMapBuiltBeforehandRunsAsOneSetDirectly) {
  const OccupancyGrid grid = asymmetricRoom();
  const OccupancyGrid moved = room(4.0, 3.0, {{2.5, 0.5, 3.0, 1.2}, {3.0, 2.0, 3.5, 2.5}});
  ParticleFilter direct(baseParams()), swapped(baseParams());
  for (ParticleFilter* f : {&direct, &swapped}) {
    f->setMap(grid);
    f->initializeGaussian({1.0, 1.5, 0.0}, diag(0.05, 0.05, 0.05));
    ASSERT_TRUE(f->update(odomOf({1.0, 1.5, 0.0}), simulateScan(grid, {1.0, 1.5, 0.0})).updated);
  }
  const OccupancyGrid* old_map = swapped.map();
  PreparedMap prepared = PreparedMap::build(moved, swapped.mapRecipe());
  // Building touched nothing of the filter: it still runs on the old map.
  EXPECT_EQ(old_map, swapped.map());
  ASSERT_TRUE(swapped.update(odomOf({1.3, 1.5, 0.0}), simulateScan(grid, {1.3, 1.5, 0.0})).updated);
  ASSERT_TRUE(direct.update(odomOf({1.3, 1.5, 0.0}), simulateScan(grid, {1.3, 1.5, 0.0})).updated);
  EXPECT_TRUE(direct.setMap(moved));
  EXPECT_TRUE(swapped.setMap(std::move(prepared)));
  for (double x : {1.6, 1.9, 2.2}) {
    const LaserScan scan = simulateScan(moved, {x, 1.5, 0.0});
    ASSERT_TRUE(direct.update(odomOf({x, 1.5, 0.0}), scan).updated);
    ASSERT_TRUE(swapped.update(odomOf({x, 1.5, 0.0}), scan).updated);
  }
  EXPECT_EQ(direct.particles().x, swapped.particles().x);
  EXPECT_EQ(direct.particles().yaw, swapped.particles().yaw);
  EXPECT_EQ(direct.estimate().pose.x, swapped.estimate().pose.x);
}

// The sensor's parameters changed while the map was being built: the model
// built with the old ones is not used.
TEST(ParticleFilter, AMapBuiltBeforeAReconfigureIsBuiltAgain) {
  ParticleFilterParams params = baseParams();
  ParticleFilter filter(params);
  PreparedMap prepared = PreparedMap::build(asymmetricRoom(), filter.mapRecipe());
  params.sensor.sigma_hit *= 2.0;
  filter.setParams(params);
  filter.setMap(std::move(prepared));
  const auto& model = dynamic_cast<const LikelihoodFieldModel&>(*filter.sensorModel());
  EXPECT_EQ(params.sensor.sigma_hit, model.params().sigma_hit);
}

// A building's floors (ros/localizer/floors.h): a map taken out with
// releaseMap and set again later is back as it was, with what its change
// layer learned, while another map was in use.
TEST(ParticleFilter, AReleasedMapComesBackWithWhatItsLayerLearned) {
  const OccupancyGrid map = room(4.0, 3.0, {{2.5, 0.5, 3.0, 1.2}});
  // The world has a box the map lacks, in view of the drive below.
  const OccupancyGrid world = room(4.0, 3.0, {{2.5, 0.5, 3.0, 1.2}, {3.2, 2.2, 3.6, 2.6}});
  ParticleFilter filter(baseParams());
  EXPECT_FALSE(filter.releaseMap().has_value());  // none yet
  filter.setMap(map);
  filter.initializeGaussian({0.8, 1.5, 0.0}, diag(0.02, 0.02, 0.02));
  for (double x = 0.8; x < 2.3; x += 0.25) {
    ASSERT_TRUE(filter.update(odomOf({x, 1.5, 0.0}), simulateScan(world, {x, 1.5, 0.0})).updated);
  }
  const MapChangeLayer::Summary learned = filter.mapChanges()->summary();
  const std::vector<std::int8_t> cells = filter.mapChanges()->occupancy();
  ASSERT_GT(learned.added, 0u);
  const OccupancyGrid* grid = filter.map();

  std::optional<PreparedMap> first = filter.releaseMap();
  ASSERT_TRUE(first.has_value());
  EXPECT_FALSE(filter.hasMap());
  EXPECT_EQ(nullptr, filter.mapChanges());
  // Another floor, learned on from scratch.
  const OccupancyGrid other = asymmetricRoom();
  filter.setMap(other);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.02, 0.02, 0.02));
  EXPECT_EQ(0u, filter.mapChanges()->summary().seen);
  ASSERT_TRUE(filter.update(odomOf({2.5, 1.5, 0.0}), simulateScan(other, {1.0, 1.5, 0.0})).updated);

  // Back: the same grid, and the layer as it was when the filter left it.
  const std::optional<PreparedMap> second = filter.releaseMap();
  ASSERT_TRUE(second.has_value());
  filter.setMap(std::move(*first));
  EXPECT_EQ(grid, filter.map());
  EXPECT_EQ(learned.added, filter.mapChanges()->summary().added);
  EXPECT_EQ(learned.seen, filter.mapChanges()->summary().seen);
  EXPECT_EQ(cells, filter.mapChanges()->occupancy());
  filter.initializeGaussian({2.3, 1.5, 0.0}, diag(0.02, 0.02, 0.02));
  // The odometry moves 0.1 m on from the other floor's last update.
  EXPECT_TRUE(filter.update(odomOf({2.6, 1.5, 0.0}), simulateScan(world, {2.4, 1.5, 0.0})).updated);
  EXPECT_LT(distance(filter.estimate().pose, {2.4, 1.5, 0.0}), 0.1);
}

}  // namespace
}  // namespace pf

// FloorSearch: global localization on every floor at once names the floor
// the scans come from, and never one it cannot tell from another.
#include "pf_localization/core/recovery/floor_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/filter/particle_filter_world.h"

namespace pf {
namespace {

using filter_world::baseParams;
using filter_world::distance;
using filter_world::odomOf;
using filter_world::room;
using filter_world::simulateScan;

// Two floors of one outline, laid out otherwise: the robot is on floor 1.
OccupancyGrid floorA() { return room(3.0, 2.0, {{1.8, 1.1, 3.0, 2.0}, {0.9, 1.5, 1.1, 1.7}}); }
OccupancyGrid floorB() {
  return room(3.0, 2.0, {{0.0, 0.0, 0.5, 0.9}, {1.3, 0.3, 1.45, 0.8}, {2.3, 1.6, 2.6, 2.0}});
}

ParticleFilterParams searchParams() {
  ParticleFilterParams p = baseParams();
  p.kld.min_particles = 500;
  p.kld.max_particles = 30000;
  return p;
}

// A drive on floor B's free space: along +x, a half turn, back along -x,
// a half turn and on along +x.
std::vector<Pose2> drive() {
  std::vector<Pose2> path{{1.0, 1.3, 0.0}};
  test::driveOn(&path, {0.25, 0.0, 0.0}, 6);
  test::driveOn(&path, {0.0, 0.0, M_PI / 4}, 4);
  test::driveOn(&path, {0.25, 0.0, 0.0}, 6);
  test::driveOn(&path, {0.0, 0.0, M_PI / 4}, 4);
  test::driveOn(&path, {0.25, 0.0, 0.0}, 4);
  return path;
}

std::vector<PreparedMap> prepared(const std::vector<OccupancyGrid>& grids) {
  std::vector<PreparedMap> maps;
  for (const OccupancyGrid& g : grids) {
    maps.push_back(PreparedMap::build(g, ParticleFilter(searchParams()).mapRecipe()));
  }
  return maps;
}

TEST(FloorSearch, NamesTheFloorTheScansComeFromAndNeverAnother) {
  const OccupancyGrid b = floorB();
  FloorSearch search(searchParams(), prepared({floorA(), b}));
  ASSERT_EQ(2u, search.floors());
  EXPECT_FALSE(search.verdict().floor.has_value());
  int found_at = -1;
  const std::vector<Pose2> path = drive();
  for (std::size_t k = 0; k < path.size(); ++k) {
    search.update(odomOf(path[k]), simulateScan(b, path[k]));
    const FloorSearch::Verdict v = search.verdict();
    ASSERT_NE(std::optional<std::size_t>(0), v.floor) << "step " << k << ": " << v.reason;
    if (v.floor && found_at < 0) found_at = static_cast<int>(k);
  }
  // Once floor 1 has explained every beam for five updates while floor 0's
  // filter, localized too, explains 86-89 %, and floor 1's is localized.
  EXPECT_GE(found_at, 0) << search.verdict().reason;
  EXPECT_LE(found_at, 20);
  EXPECT_LT(distance(path.back(), search.filter(1).estimate().pose), 0.2);
  const std::vector<PreparedMap> back = search.release();
  ASSERT_EQ(2u, back.size());
  EXPECT_EQ(b.data(), back[1].model->field().grid().data());
}

TEST(FloorSearch, NeverNamesOneOfTwoFloorsThatLookAlike) {
  const OccupancyGrid b = floorB();
  FloorSearch search(searchParams(), prepared({b, b}));
  for (const Pose2& at : drive()) {
    search.update(odomOf(at), simulateScan(b, at));
    EXPECT_FALSE(search.verdict().floor.has_value()) << search.verdict().reason;
  }
  // Either no floor is localized, or both are and explain the scans alike.
  const std::string reason = search.verdict().reason;
  EXPECT_TRUE(reason.find("cannot tell") != std::string::npos ||
              reason.find("not localized") != std::string::npos)
      << reason;
}

// Each floor's filter draws its own stream, from the filter's seed: floor 0
// the seed itself; the same seed gives the same search, another seed another.
TEST(FloorSearch, EachFloorDrawsItsOwnStreamFromTheSeed) {
  EXPECT_EQ(7u, floorSeed(7, 0));
  EXPECT_NE(floorSeed(7, 1), floorSeed(7, 0));
  EXPECT_NE(floorSeed(7, 1), floorSeed(8, 1));
  const OccupancyGrid b = floorB();
  const auto run = [&](uint64_t seed) {
    ParticleFilterParams params = searchParams();
    params.seed = seed;
    FloorSearch search(params, prepared({b, b}));
    const std::vector<Pose2> path = drive();
    for (std::size_t k = 0; k < 3; ++k) search.update(odomOf(path[k]), simulateScan(b, path[k]));
    return std::vector<Pose2>{search.filter(0).estimate().pose, search.filter(1).estimate().pose};
  };
  const std::vector<Pose2> one = run(7), again = run(7), other = run(8);
  EXPECT_EQ(one[0].x, again[0].x);
  EXPECT_EQ(one[1].y, again[1].y);
  // The same map on both floors: only the seeds tell their filters apart.
  EXPECT_NE(one[0].x, one[1].x);
  EXPECT_NE(one[0].x, other[0].x);
}

}  // namespace
}  // namespace pf

// The layer of where the world no longer matches its map
// (map_change_layer.h): a room whose map lacks one box and has another that
// is gone, scanned from a few poses.
#include "pf_localization/core/map/map_change_layer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pf_localization/core/map/map_loader.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

using test::Box;
using test::changedRoomMap;
using test::changedRoomTour;
using test::changedRoomWorld;
using test::kChangedRoomAdded;
using test::kChangedRoomRemoved;
using test::room;
using test::scan360;
using test::simulateScan;

// The cells of `box` and one cell round it in state `c`: a beam's end
// point lies in the cell before a face as often as in the face's.
int cellsIn(const MapChangeLayer& layer, const OccupancyGrid& grid, const Box& box,
            MapChangeLayer::Cell c) {
  const double r = grid.resolution();
  const CellIndex lo = grid.worldToCell(box.x0 - r, box.y0 - r),
                  hi = grid.worldToCell(box.x1 + r, box.y1 + r);
  int n = 0;
  for (int y = lo.y; y <= hi.y; ++y) {
    for (int x = lo.x; x <= hi.x; ++x) n += layer.cell(x, y) == c;
  }
  return n;
}

// The layer after the tour, each pose scanned `times` times.
MapChangeLayer toured(const OccupancyGrid& map, const OccupancyGrid& seen, int times) {
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  for (int k = 0; k < times; ++k) {
    for (const Pose2& p : changedRoomTour()) layer.add(scan360(seen, p), p);
  }
  return layer;
}

TEST(MapChangeLayer, AWorldAsMappedHasNoChange) {
  const MapChangeLayer layer = toured(changedRoomMap(), changedRoomMap(), 3);
  const MapChangeLayer::Summary s = layer.summary();
  EXPECT_GT(s.seen, 3000u);
  EXPECT_EQ(0u, s.added);
  EXPECT_EQ(0u, s.removed);
  EXPECT_EQ(15u, layer.scans());
}

TEST(MapChangeLayer, FindsWhatTheMapLacksAndWhatIsGone) {
  const OccupancyGrid map = changedRoomMap();
  const MapChangeLayer layer = toured(map, changedRoomWorld(), 3);
  // The added box's faces towards the tour are hit: a 0.6 m face is 12 cells.
  EXPECT_GE(cellsIn(layer, map, kChangedRoomAdded, MapChangeLayer::Cell::kAdded), 16);
  // The gone box is seen through: most of its 13 x 13 cells.
  EXPECT_GE(cellsIn(layer, map, kChangedRoomRemoved, MapChangeLayer::Cell::kRemoved), 100);
  // Nothing else: every changed cell is one of the boxes'.
  const MapChangeLayer::Summary s = layer.summary();
  EXPECT_EQ(s.added, static_cast<std::size_t>(
                         cellsIn(layer, map, kChangedRoomAdded, MapChangeLayer::Cell::kAdded)));
  EXPECT_EQ(s.removed, static_cast<std::size_t>(cellsIn(layer, map, kChangedRoomRemoved,
                                                        MapChangeLayer::Cell::kRemoved)));
}

TEST(MapChangeLayer, OneGlimpseIsNotAChange) {
  // One scan is fewer than kMinScans, however many of its beams hit a cell.
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  const Pose2 p = changedRoomTour().front();
  layer.add(scan360(changedRoomWorld(), p), p);
  EXPECT_EQ(0u, layer.summary().added);
}

TEST(MapChangeLayer, WhatOnePlaceSawIsAddedUntilSeenThrough) {
  // The box seen only from where the robot turned in place: a cupboard seen
  // from one spot, or someone standing by. Hit by every scan and never seen
  // through, it is added (the planter, the reception desk and the lab's
  // cabinets of changed_30.bag are seen so)...
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  const Pose2 p = changedRoomTour().front();
  for (int k = 0; k < 6; ++k) {
    const Pose2 turned{p.x, p.y, p.yaw + 0.6 * k};
    layer.add(scan360(changedRoomWorld(), turned), turned);
  }
  const std::size_t added = layer.summary().added;
  EXPECT_GE(cellsIn(layer, map, kChangedRoomAdded, MapChangeLayer::Cell::kAdded), 5);
  EXPECT_EQ(static_cast<std::size_t>(
                cellsIn(layer, map, kChangedRoomAdded, MapChangeLayer::Cell::kAdded)),
            added);
  // ...until kOnePlaceClearScans scans in a row see its place empty, fewer
  // than a cell hit from places apart needs (kClearScans): the person left.
  // One is not enough (a beam grazing an edge).
  static_assert(MapChangeLayer::kOnePlaceClearScans < MapChangeLayer::kClearScans);
  const Pose2 r{p.x - 0.3, p.y + 0.2, 0.4};
  for (int k = 1; k < MapChangeLayer::kOnePlaceClearScans; ++k) {
    layer.add(scan360(map, r), r);
    EXPECT_EQ(added, layer.summary().added) << k;
  }
  layer.add(scan360(map, p), p);
  EXPECT_EQ(0u, layer.summary().added);
}

TEST(MapChangeLayer, SomeoneStandingByIsNotAWall) {
  // The box as a person standing by, seen from two places kMinBaseline
  // apart, as a cupboard is from the robot driving past: it is added...
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  const Pose2 p = changedRoomTour().front();
  const Pose2 q{p.x, p.y - MapChangeLayer::kMinBaseline - 0.05, p.yaw};
  layer.add(scan360(changedRoomWorld(), p), p);
  layer.add(scan360(changedRoomWorld(), q), q);
  const std::size_t added = layer.summary().added;
  EXPECT_GE(cellsIn(layer, map, kChangedRoomAdded, MapChangeLayer::Cell::kAdded), 5);
  EXPECT_EQ(static_cast<std::size_t>(
                cellsIn(layer, map, kChangedRoomAdded, MapChangeLayer::Cell::kAdded)),
            added);
  // ...and once the place is seen empty (kClearScans scans in a row), from
  // wherever, it is gone from the layer, however many scans hit it before:
  // the person left. Fewer scans through it are not enough (a beam grazing
  // a face).
  const Pose2 r{p.x - 0.3, p.y + 0.2, 0.4};
  for (int k = 1; k < MapChangeLayer::kClearScans; ++k) {
    layer.add(scan360(map, r), r);
    EXPECT_EQ(added, layer.summary().added) << k;
  }
  layer.add(scan360(map, p), p);
  EXPECT_EQ(0u, layer.summary().added);
  // Seen again, it is back.
  layer.add(scan360(changedRoomWorld(), p), p);
  EXPECT_GT(layer.summary().added, 0u);
}

TEST(MapChangeLayer, WhatMovedInWhileTheRobotLookedIsNotAWall) {
  // The box's place seen empty from nearby (within kMovedInRange) before
  // anything stood there: what stops the beams there later came while the
  // robot looked, a person walking up, and is added only after
  // kMovedInScans scans hit it, however many places they came from.
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  const Pose2 near{3.2, 2.0, 0.0};  // 0.8 m from the box's west face
  for (int k = 0; k < MapChangeLayer::kMovedInPasses; ++k) {
    const Pose2 p{near.x, near.y + 0.05 * k, 0.6 * k};
    layer.add(scan360(map, p), p);
  }
  const std::vector<Pose2> places = {{3.0, 2.0, 0.0},  {2.6, 1.2, 0.5}, {2.0, 1.0, 1.6},
                                     {3.2, 2.8, -2.0}, {2.5, 2.2, 3.0}, {3.0, 1.0, 0.3},
                                     {2.2, 2.9, -0.5}, {3.1, 3.1, -1.0}};
  for (std::size_t k = 0; k + 1 < static_cast<std::size_t>(MapChangeLayer::kMovedInScans); ++k) {
    layer.add(scan360(changedRoomWorld(), places[k]), places[k]);
  }
  // The west face, passed from near before, is not added yet...
  const Box west{kChangedRoomAdded.x0 - 0.05, kChangedRoomAdded.y0 + 0.1,
                 kChangedRoomAdded.x0 + 0.05, kChangedRoomAdded.y1 - 0.1};
  EXPECT_EQ(0, cellsIn(layer, map, west, MapChangeLayer::Cell::kAdded));
  // ...and is, a pallet put down for good, once kMovedInScans hit it.
  for (int round = 0; round < 3; ++round) {
    for (const Pose2& p : places) layer.add(scan360(changedRoomWorld(), p), p);
  }
  EXPECT_GT(cellsIn(layer, map, west, MapChangeLayer::Cell::kAdded), 5);
}

TEST(MapChangeLayer, ListsEachCellThatBecameOrStoppedBeingAChange) {
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  for (int k = 0; k < 3; ++k) {
    for (const Pose2& p : changedRoomTour()) layer.add(scan360(changedRoomWorld(), p), p);
  }
  std::vector<std::size_t> changed = layer.takeChangedCells();
  const MapChangeLayer::Summary s = layer.summary();
  std::size_t now = 0;
  for (std::size_t i : changed) now += layer.added(i) || layer.removed(i);
  // Each changed cell is listed, perhaps more than once, and taken once.
  EXPECT_GE(now, s.added + s.removed);
  EXPECT_TRUE(layer.takeChangedCells().empty());
  // Forgetting lists every cell that was a change, none of them one now.
  layer.clear();
  changed = layer.takeChangedCells();
  EXPECT_GE(changed.size(), s.added + s.removed);
  for (std::size_t i : changed) EXPECT_FALSE(layer.added(i) || layer.removed(i));
}

TEST(MapChangeLayer, WritesTheMasksConvention) {
  const OccupancyGrid map = changedRoomMap();
  const MapChangeLayer layer = toured(map, changedRoomWorld(), 3);
  const std::vector<std::uint8_t> pixels = layer.pixels();
  const std::vector<std::int8_t> values = layer.occupancy();
  ASSERT_EQ(map.data().size(), pixels.size());
  ASSERT_EQ(map.data().size(), values.size());
  std::size_t added = 0, removed = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    added += pixels[i] == 0;
    removed += pixels[i] == 205;
    EXPECT_EQ(pixels[i] == 128, values[i] == -1);
    EXPECT_EQ(pixels[i] == 0, values[i] == 100);
    EXPECT_EQ(values[i],
              MapChangeLayer::valueOf(layer.removed(i)  ? MapChangeLayer::Cell::kRemoved
                                      : layer.added(i)  ? MapChangeLayer::Cell::kAdded
                                      : values[i] == -1 ? MapChangeLayer::Cell::kUnseen
                                                        : MapChangeLayer::Cell::kAsMapped));
  }
  EXPECT_GT(added, 0u);
  EXPECT_GT(removed, 0u);
  EXPECT_EQ(layer.summary().added, added);
  EXPECT_EQ(layer.summary().removed, removed);
  // Into storage used before, longer and holding other values: the same.
  std::vector<std::int8_t> reused(values.size() + 7, 42);
  layer.occupancy(&reused);
  EXPECT_EQ(values, reused);
  EXPECT_THROW(saveImage(map, std::vector<std::uint8_t>(3), "/tmp/x.yaml"), std::invalid_argument);
}

}  // namespace
}  // namespace pf

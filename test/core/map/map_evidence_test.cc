// What each beam says about the map from a pose (map_evidence.h), and the
// beams left out while the tracked pose explains the rest (map_change_mask.h):
// a world that differs from its map by a box, seen from the right pose and
// from a wrong one.
#include "pf_localization/core/map/map_evidence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pf_localization/core/map/map_change_mask.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

using test::asymmetricRoom;
using test::Box;
using test::room;
using test::simulateScan;

// A 6 x 4 m room with a 0.6 x 0.6 m box at x 4.0-4.6, y 1.7-2.3 (when
// `box`), and a robot at the room's middle facing +x: the box is 1 m ahead.
OccupancyGrid boxRoom(bool box) {
  return room(6.0, 4.0, 0.05, box ? std::vector<Box>{{4.0, 1.7, 4.6, 2.3}} : std::vector<Box>{});
}
const Pose2 kRobot{3.0, 2.0, 0.0};

// The evidence of the beam straight ahead (range `range`) from kRobot.
BeamEvidence ahead(const MapEvidence& evidence, double range) {
  return evidence.judge(kRobot.x, kRobot.y, kRobot.yaw, range);
}

// The row-major index of the cell holding (x, y).
std::size_t indexAt(const OccupancyGrid& map, double x, double y) {
  const CellIndex c = map.worldToCell(x, y);
  return static_cast<std::size_t>(c.y) * map.width() + c.x;
}

TEST(MapEvidence, ABeamEndingOnTheMapsWallIsOnTheMap) {
  const DistanceField field(boxRoom(false), 2.0);
  const MapEvidence evidence(field);
  // The east wall's inner face is at x 5.95: 2.95 m ahead.
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.95));
  // A few centimetres of pose error change nothing.
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.90));
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 3.0));
}

TEST(MapEvidence, ABeamStoppedByWhatTheMapLacksIsShortOfIt) {
  // The world has the box, the map does not: the beam stops 1 m ahead where
  // the map would let it run to the wall.
  const DistanceField field(boxRoom(false), 2.0);
  const MapEvidence evidence(field);
  EXPECT_EQ(BeamEvidence::kShortOfMap, ahead(evidence, 1.0));
  // Within kShortMargin of the mapped wall it is the wall.
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.95 - 0.2));
}

TEST(MapEvidence, ABeamThroughAMappedObjectThatIsGoneEndsBehindIt) {
  // The map has the box, the world does not: the beam passes where the box
  // was and ends on the wall behind it, or in the open.
  const DistanceField field(boxRoom(true), 2.0);
  const MapEvidence evidence(field);
  EXPECT_EQ(BeamEvidence::kThroughOntoMap, ahead(evidence, 2.95));
  EXPECT_EQ(BeamEvidence::kThroughIntoOpen, ahead(evidence, 2.3));
  // Ending on the box's face is on the map; a little inside it, too.
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 1.0));
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 1.2));
}

TEST(MapEvidence, AnObstacleLearnedGoneLetsRaysThroughAndLearnedBackStopsThem) {
  const OccupancyGrid map = boxRoom(true);
  const DistanceField field(map, 2.0);
  MapEvidence evidence(field);
  ASSERT_EQ(BeamEvidence::kThroughOntoMap, ahead(evidence, 2.95));
  // Every cell of the box learned gone: the beam to the wall behind it is
  // on the map as the world has it.
  std::vector<std::size_t> box;
  for (std::size_t i = 0; i < map.data().size(); ++i) {
    const CellIndex c{static_cast<int>(i % map.width()), static_cast<int>(i / map.width())};
    double x, y;
    map.cellToWorld(c, &x, &y);
    if (x > 3.9 && x < 4.7 && y > 1.6 && y < 2.4 && map.state(c) == CellState::kOccupied) {
      box.push_back(i);
    }
  }
  ASSERT_GT(box.size(), 100u);
  for (std::size_t i : box) evidence.setGone(i, true);
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.95));
  // A free cell cannot be gone: marking one changes nothing.
  evidence.setGone(indexAt(map, 3.5, 2.0), true);
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.95));
  for (std::size_t i : box) evidence.setGone(i, false);
  EXPECT_EQ(BeamEvidence::kThroughOntoMap, ahead(evidence, 2.95));
}

TEST(MapEvidence, AnEndOnAnObjectLearnedAddedSeesAChangeEvenBesideTheMap) {
  // The world has a cabinet 0.2 m deep against the east wall (x 5.75-5.95):
  // a beam ending on its face, 2.75 m ahead, ends within the wall's short
  // margin, and looks on the map...
  const OccupancyGrid map = boxRoom(false);
  const DistanceField field(map, 2.0);
  MapEvidence evidence(field);
  ASSERT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.75));
  // ...until the layer has learned the face added.
  const std::size_t face = indexAt(map, kRobot.x + 2.75, kRobot.y);
  evidence.setAdded(face, true);
  EXPECT_EQ(BeamEvidence::kShortOfMap, ahead(evidence, 2.75));
  // An end on the mapped wall beside it stays on the map.
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.95));
  evidence.setAdded(face, false);
  EXPECT_EQ(BeamEvidence::kOnMap, ahead(evidence, 2.75));
}

TEST(MapEvidence, ABeamOffTheMapIsOffItButJustPastTheEdgeIsJudgedThere) {
  const DistanceField field(boxRoom(false), 2.0);
  const MapEvidence evidence(field);
  // The map ends at x 6.0: a beam ending 0.1 m past it (0.15 m past the
  // wall's face, within kThroughMargin) ends on the wall drawn at the edge,
  // one ending 2 m past it left the map.
  EXPECT_EQ(BeamEvidence::kOnMap, evidence.judge(kRobot.x, kRobot.y, 0.0, 3.1));
  EXPECT_EQ(BeamEvidence::kOffMap, evidence.judge(kRobot.x, kRobot.y, 0.0, 5.0));
}

TEST(MapEvidence, AScanIsJudgedEveryFewBeamsAndEachVerdictIsItsNeighbours) {
  const OccupancyGrid world = boxRoom(true);
  const DistanceField field(boxRoom(false), 2.0);
  const MapEvidence evidence(field);
  std::vector<BeamEvidence> per_beam;
  const LaserScan scan = simulateScan(world, kRobot);
  ASSERT_GT(scan.ranges.size(), MapEvidence::kJudgedBeams);
  const EvidenceCounts c = evidence.judge(scan, kRobot, &per_beam);
  ASSERT_EQ(scan.ranges.size(), per_beam.size());
  // At most kJudgedBeams beams judged: the box, about 33 degrees of the scan
  // from 1 m, stops some short of the map; every other ends on a wall.
  EXPECT_LE(c.beams(), MapEvidence::kJudgedBeams);
  EXPECT_GT(c.short_of_map, 0u);
  EXPECT_EQ(c.beams(), c.on_map + c.short_of_map);
  EXPECT_EQ(0.0, c.contradicting());
  // Every beam with a reading has its judged neighbour's verdict.
  std::size_t shorts = 0;
  for (std::size_t i = 0; i < per_beam.size(); ++i) {
    const bool reading = isReading(scan.ranges[i], scan.range_min, scan.range_max);
    EXPECT_EQ(!reading, per_beam[i] == BeamEvidence::kNoReading) << i;
    shorts += per_beam[i] == BeamEvidence::kShortOfMap ? 1 : 0;
  }
  EXPECT_GE(shorts, c.short_of_map);
  EXPECT_LE(shorts, c.short_of_map * (scan.ranges.size() / MapEvidence::kJudgedBeams));
}

std::size_t maskedCount(const LaserScan& scan) {
  std::size_t n = 0;
  for (float r : scan.ranges) n += std::isnan(r) ? 1 : 0;
  return n;
}

TEST(MapChangeMask, AtTheRightPoseTheBeamsSeeingTheChangeAreMasked) {
  const OccupancyGrid world = boxRoom(true);
  const DistanceField field(boxRoom(false), 2.0);
  const MapEvidence evidence(field);
  const LaserScan scan = simulateScan(world, kRobot);
  MapChangeMask mask;
  std::vector<LaserScan> storage;
  const ScanGroup out = mask.mask(evidence, scan, kRobot, &storage);
  ASSERT_EQ(1u, out.size());
  // Masked: the beams judged short of the map, with their neighbours.
  std::vector<BeamEvidence> per_beam;
  evidence.judge(scan, kRobot, &per_beam);
  int shorts = 0;
  for (BeamEvidence e : per_beam) shorts += e == BeamEvidence::kShortOfMap ? 1 : 0;
  EXPECT_EQ(shorts, mask.masked());
  EXPECT_GT(mask.masked(), 0);
  EXPECT_EQ(static_cast<std::size_t>(mask.masked()), maskedCount(out[0]) - maskedCount(scan));
  EXPECT_GT(mask.changedShare(), 0.0);
  EXPECT_LT(mask.changedShare(), 0.2);
}

TEST(MapChangeMask, FromAWrongPoseNothingIsMasked) {
  // The odometry fault tests' room, the robot 0.6 m behind where the pose
  // says: beams run through its walls and off the map, and nothing may be
  // hidden from the filter that has to find that out.
  const OccupancyGrid grid = asymmetricRoom();
  const DistanceField field(grid, 2.0);
  const MapEvidence evidence(field);
  const LaserScan scan = simulateScan(grid, {1.2, 1.5, 0.0});
  MapChangeMask mask;
  std::vector<LaserScan> storage;
  const ScanGroup out = mask.mask(evidence, scan, {1.8, 1.5, 0.0}, &storage);
  EXPECT_EQ(0, mask.masked());
  EXPECT_EQ(&scan, &out[0]);
  EXPECT_GT(mask.counts().short_of_map, 0u);
  EXPECT_GT(mask.counts().contradicting(), 0.0);
}

}  // namespace
}  // namespace pf

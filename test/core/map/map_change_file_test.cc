// The layer of the map's changes saved and restored (map_change_file.h,
// MapChangeLayer::encode() and decode()): a room whose map lacks one box and
// has another that is gone, toured, written and read back.
#include "pf_localization/core/map/map_change_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "pf_localization/core/filter/beam_screen.h"
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

void tourOnce(MapChangeLayer* layer, const OccupancyGrid& seen) {
  for (const Pose2& p : changedRoomTour()) layer->add(scan360(seen, p), p);
}

void expectSameSummary(const MapChangeLayer& a, const MapChangeLayer& b) {
  const MapChangeLayer::Summary s = a.summary(), t = b.summary();
  EXPECT_EQ(s.seen, t.seen);
  EXPECT_EQ(s.added, t.added);
  EXPECT_EQ(s.removed, t.removed);
  EXPECT_EQ(s.added_scans, t.added_scans);
  EXPECT_EQ(s.removed_scans, t.removed_scans);
  EXPECT_EQ(a.scans(), b.scans());
}

TEST(MapChangeFile, RestoresTheLayerAndItsCounts) {
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer learned(field);
  tourOnce(&learned, changedRoomWorld());
  tourOnce(&learned, changedRoomWorld());
  ASSERT_GT(learned.summary().added, 0u);
  ASSERT_GT(learned.summary().removed, 0u);

  const MapChangesFileContents read = readMapChangesFile(mapChangesFile(learned, "the room"));
  ASSERT_EQ("", read.error);
  EXPECT_EQ("the room", read.map_signature);
  MapChangeLayer restored(field);
  ASSERT_EQ("", restored.decode(read.state));
  EXPECT_EQ(learned.occupancy(), restored.occupancy());
  expectSameSummary(learned, restored);
  // Each added or removed cell is listed for the judging of scans.
  std::size_t listed = 0;
  for (const std::size_t i : restored.takeChangedCells())
    listed += restored.added(i) || restored.removed(i);
  EXPECT_EQ(learned.summary().added + learned.summary().removed, listed);

  // The counts came back too, not only the picture: the same scans on both
  // go on to the same layer. Seen as mapped now, the box's cells go back to
  // as mapped on both at the same scan.
  for (int k = 0; k < 3; ++k) {
    tourOnce(&learned, map);
    tourOnce(&restored, map);
    EXPECT_EQ(learned.occupancy(), restored.occupancy()) << "tour " << k;
    expectSameSummary(learned, restored);
  }
}

TEST(MapChangeFile, ReportsTheEvidenceBehindEachChange) {
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  tourOnce(&layer, changedRoomWorld());
  const MapChangeLayer::Summary once = layer.summary();
  ASSERT_GT(once.added, 0u);
  tourOnce(&layer, changedRoomWorld());
  const MapChangeLayer::Summary twice = layer.summary();
  // Each change has at least kMinScans scans behind it, and a second tour of
  // the same world adds to them.
  EXPECT_GE(once.added_scans, MapChangeLayer::kMinScans * once.added);
  EXPECT_GE(once.removed_scans, MapChangeLayer::kMinScans * once.removed);
  EXPECT_GT(twice.added_scans * once.added, once.added_scans * twice.added);
  EXPECT_GT(twice.removed_scans * once.removed, once.removed_scans * twice.removed);
}

TEST(MapChangeFile, AWideMapSeenInPartIsSmall) {
  // 2000 x 2000 cells, a room of 6 x 4 m in its corner toured.
  const OccupancyGrid map =
      room(100.0, 100.0, 0.05, {kChangedRoomRemoved, {6.0, 0.0, 6.1, 4.1}, {0.0, 4.0, 6.1, 4.1}});
  const OccupancyGrid seen =
      room(100.0, 100.0, 0.05, {kChangedRoomAdded, {6.0, 0.0, 6.1, 4.1}, {0.0, 4.0, 6.1, 4.1}});
  const DistanceField field(map, 2.0);
  MapChangeLayer layer(field);
  tourOnce(&layer, seen);
  tourOnce(&layer, seen);
  ASSERT_GT(layer.summary().added, 0u);
  const std::string bytes = mapChangesFile(layer, "wide");
  // Measured: 5.4 kB for 8 900 cells seen of 4 million.
  EXPECT_LT(bytes.size(), 16000u) << "of " << map.data().size() << " cells";
  MapChangeLayer restored(field);
  ASSERT_EQ("", restored.decode(readMapChangesFile(bytes).state));
  EXPECT_EQ(layer.occupancy(), restored.occupancy());
}

TEST(MapChangeFile, RefusesAFileCutShortOrAltered) {
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer learned(field);
  tourOnce(&learned, changedRoomWorld());
  tourOnce(&learned, changedRoomWorld());
  const std::string bytes = mapChangesFile(learned, "the room");
  for (std::size_t n = 0; n < bytes.size(); n += n < 200 ? 1 : 97) {
    EXPECT_NE("", readMapChangesFile(bytes.substr(0, n)).error) << n << " of " << bytes.size();
  }
  EXPECT_NE("", readMapChangesFile(bytes.substr(0, bytes.size() - 1)).error);
  EXPECT_NE("", readMapChangesFile(bytes + "x").error);
  std::string altered = bytes;
  altered[altered.size() / 2] ^= 0x10;
  EXPECT_NE(std::string::npos, readMapChangesFile(altered).error.find("checksum"));
  EXPECT_EQ("not a map changes file", readMapChangesFile("P5\n6 4\n255\n").error);
  std::string newer = bytes;
  newer[newer.find('\n') + 1] = 3;  // the version's lowest byte
  EXPECT_NE(std::string::npos, readMapChangesFile(newer).error.find("version 3"));

  // The state itself cut short, past the checksum's guard: refused, the
  // layer left empty, never read past its end.
  const std::string state = learned.encode();
  MapChangeLayer layer(field);
  for (std::size_t n = 0; n < state.size(); n += n < 300 ? 1 : 41) {
    EXPECT_NE("", layer.decode(state.substr(0, n))) << n << " of " << state.size();
    EXPECT_EQ(0u, layer.summary().seen);
    EXPECT_EQ(0u, layer.scans());
  }
  EXPECT_NE("", layer.decode(state + '\0'));
  EXPECT_EQ("", layer.decode(state));
}

TEST(MapChangeFile, RefusesAnotherMapsLayer) {
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer learned(field);
  tourOnce(&learned, changedRoomWorld());
  tourOnce(&learned, changedRoomWorld());
  const OccupancyGrid taller = room(6.0, 4.5, 0.05, {kChangedRoomRemoved});
  const DistanceField taller_field(taller, 2.0);
  MapChangeLayer other(taller_field);
  const std::string error = other.decode(learned.encode());
  EXPECT_NE(std::string::npos, error.find("120 x 80")) << error;
  EXPECT_EQ(0u, other.summary().seen);
  // A map of the same size whose cells differ: a cell seen there is unknown
  // here, or a beam ended in what is an obstacle here.
  const OccupancyGrid unknown(map.width(), map.height(), map.resolution(), map.origin(),
                              std::vector<std::int8_t>(map.data().size(), -1));
  const DistanceField unknown_field(unknown, 2.0);
  MapChangeLayer blind(unknown_field);
  EXPECT_NE("", blind.decode(learned.encode()));
  EXPECT_EQ(0u, blind.summary().seen);
}

TEST(MapChangeFile, ARestoredLayerIsWhatTheScansAreJudgedOn) {
  const OccupancyGrid map = changedRoomMap();
  const DistanceField field(map, 2.0);
  MapChangeLayer learned(field);
  tourOnce(&learned, changedRoomWorld());
  tourOnce(&learned, changedRoomWorld());
  BeamScreen screen;
  screen.setMap(BeamScreen::prepare(field));
  // A beam from the west wall along the removed box's row to the east wall.
  const auto judged = [&screen] { return screen.evidence()->judge(0.5, 2.9, 0.0, 5.45); };
  EXPECT_EQ(BeamEvidence::kThroughOntoMap, judged());
  ASSERT_EQ("", screen.restoreLayer(learned.encode()));
  EXPECT_EQ(learned.occupancy(), screen.layer()->occupancy());
  EXPECT_EQ(BeamEvidence::kOnMap, judged());  // the box is gone
  screen.clearLayer();
  EXPECT_EQ(0u, screen.layer()->summary().seen);
  EXPECT_EQ(BeamEvidence::kThroughOntoMap, judged());
  EXPECT_NE("", screen.restoreLayer(learned.encode().substr(0, 40)));
  EXPECT_EQ(BeamEvidence::kThroughOntoMap, judged());
}

}  // namespace
}  // namespace pf

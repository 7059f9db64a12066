#include "pf_localization/sim/map_changes.h"

#include <gtest/gtest.h>

#include <sstream>

#include "support/grid_from_rows.h"

namespace pf::sim {
namespace {

MapChanges parse(const std::string& text) {
  std::istringstream in(text);
  return parseMapChanges(in, "test.changes");
}

// The message that parsing (and, with `map`, applying) `text` throws, or "".
std::string errorOf(const std::string& text, const OccupancyGrid* map = nullptr) {
  try {
    const MapChanges changes = parse(text);
    if (map) applyMapChanges(*map, changes);
  } catch (const MapChangesError& e) {
    return e.what();
  }
  return "";
}

// A 7 x 5 m room of 1 m cells drawn by hand (row 0 at the bottom, cell
// (i, j)'s centre at (i + 0.5, j + 0.5)): walls around, a 2-cell table at
// cells (3, 2) and (4, 2), and one unknown cell at (5, 1). 22 cells occupied.
OccupancyGrid room() {
  return test::gridFromRows({"#######",  //
                             "#.....#",  //
                             "#..##.#",  //
                             "#....?#",  //
                             "#######"},
                            1.0);
}

// The world and its mask side by side, row by row from the top as room()
// draws them: the world '#' occupied, '.' free, '?' unknown; the mask '+'
// added, '-' removed, '.' unchanged.
std::vector<std::string> picture(const ChangedWorld& w) {
  std::vector<std::string> rows;
  for (int j = w.world.height() - 1; j >= 0; --j) {
    std::string world, mask;
    for (int i = 0; i < w.world.width(); ++i) {
      const CellState s = w.world.state({i, j});
      world += s == CellState::kOccupied ? '#' : s == CellState::kFree ? '.' : '?';
      const CellChange c = w.mask[w.world.linearIndex({i, j})];
      mask += c == CellChange::kAdded ? '+' : c == CellChange::kRemoved ? '-' : '.';
    }
    rows.push_back(world + " " + mask);
  }
  return rows;
}

ChangedWorld apply(const std::string& text) { return applyMapChanges(room(), parse(text)); }

TEST(MapChangesTest, ParsesEveryCommandWithItsLine) {
  const MapChanges m = parse(
      "# furniture\n"
      "\n"
      "add 1 2 3 4        # a cabinet\n"
      "add_disc 2 3 0.5\n"
      "remove 0 0 1 1\n"
      "move 1 1 2 2 -0.5 3\n");
  EXPECT_EQ(m.file, "test.changes");
  ASSERT_EQ(m.changes.size(), 4u);
  EXPECT_EQ(m.changes[0].kind, MapChange::Kind::kAdd);
  EXPECT_EQ(m.changes[0].line, 3);
  EXPECT_DOUBLE_EQ(m.changes[0].box.x0, 1.0);
  EXPECT_DOUBLE_EQ(m.changes[0].box.y1, 4.0);
  EXPECT_EQ(m.changes[1].kind, MapChange::Kind::kAddDisc);
  EXPECT_DOUBLE_EQ(m.changes[1].box.x0, 1.5);  // the disc's bounds
  EXPECT_DOUBLE_EQ(m.changes[1].box.y1, 3.5);
  EXPECT_EQ(m.changes[2].kind, MapChange::Kind::kRemove);
  EXPECT_EQ(m.changes[2].line, 5);
  EXPECT_EQ(m.changes[3].kind, MapChange::Kind::kMove);
  EXPECT_DOUBLE_EQ(m.changes[3].dx, -0.5);
  EXPECT_DOUBLE_EQ(m.changes[3].dy, 3.0);
  EXPECT_EQ(m.changes[3].line, 6);
}

TEST(MapChangesTest, ParseErrorsNameTheLine) {
  EXPECT_EQ(errorOf("add 0 0 1 1\n\ngrow 1 2 3 4\n"),
            "test.changes:3: unknown command 'grow' (expected add, add_disc, remove or move)");
  EXPECT_EQ(errorOf("# x\nadd 0 0 1\n"),
            "test.changes:2: 'add' takes 4 number(s): add x0 y0 x1 y1");
  EXPECT_EQ(errorOf("remove 0 0 1 one\n"), "test.changes:1: 'one' is not a number (in 'remove')");
  EXPECT_EQ(errorOf("\n\n\nadd 2 0 1 1\n"),
            "test.changes:4: the box must have x0 < x1 and y0 < y1 (in 'add')");
  EXPECT_EQ(errorOf("remove 0 1 1 1\n"),
            "test.changes:1: the box must have x0 < x1 and y0 < y1 (in 'remove')");
  EXPECT_EQ(errorOf("add_disc 1 1 0\n"),
            "test.changes:1: the radius must be positive, got 0.000000");
  EXPECT_EQ(errorOf("move 0 0 1 1 0 0\n"), "test.changes:1: 'move' by (0, 0) moves nothing");
  EXPECT_EQ(errorOf("add 0 0 1 inf\n"), "test.changes:1: 'inf' is not a number (in 'add')");
}

TEST(MapChangesTest, NoChangesGiveTheMap) {
  const ChangedWorld w = apply("# nothing changed\n");
  EXPECT_EQ(w.world.data(), room().data());
  EXPECT_EQ(w.added, 0);
  EXPECT_EQ(w.removed, 0);
  EXPECT_EQ(w.map_occupied, 22);
  EXPECT_DOUBLE_EQ(w.changedShare(), 0.0);
}

TEST(MapChangesTest, AddFillsTheCellsWhoseCentresAreInTheBox) {
  // Centres (1.5, 3.5) and (2.5, 3.5) are inside; (3.5, 3.5) is not.
  const ChangedWorld w = apply("add 1.2 3.0 3.0 3.9\n");
  EXPECT_EQ(picture(w), (std::vector<std::string>{"####### .......",  //
                                                  "###...# .++....",  //
                                                  "#..##.# .......",  //
                                                  "#....?# .......",  //
                                                  "####### ......."}));
  EXPECT_EQ(w.added, 2);
  EXPECT_EQ(w.removed, 0);
  EXPECT_DOUBLE_EQ(w.changedShare(), 2.0 / 22.0);
}

TEST(MapChangesTest, AddOnAnUnknownCellCountsAsAdded) {
  const ChangedWorld w = apply("add 5 1 6 2\n");
  EXPECT_EQ(w.world.state({5, 1}), CellState::kOccupied);
  EXPECT_EQ(w.mask[w.world.linearIndex({5, 1})], CellChange::kAdded);
  EXPECT_EQ(w.added, 1);
}

TEST(MapChangesTest, RemoveFreesOnlyOccupiedCells) {
  // The box takes the table and the unknown cell: the table goes, the
  // unknown cell stays unknown, the free cells stay free.
  const ChangedWorld w = apply("remove 2.6 1.1 5.9 2.9   # the table\n");
  EXPECT_EQ(picture(w), (std::vector<std::string>{"####### .......",  //
                                                  "#.....# .......",  //
                                                  "#.....# ...--..",  //
                                                  "#....?# .......",  //
                                                  "####### ......."}));
  EXPECT_EQ(w.added, 0);
  EXPECT_EQ(w.removed, 2);
  EXPECT_DOUBLE_EQ(w.changedShare(), 2.0 / 22.0);
}

TEST(MapChangesTest, MoveCountsOnlyTheCellsLeftAndEntered) {
  // The table one cell west: it leaves (4, 2), enters (2, 2), and (3, 2)
  // stays occupied. 0.6 m rounds to one 1 m cell.
  const ChangedWorld w = apply("move 3 2 5 3 -0.6 0\n");
  EXPECT_EQ(picture(w), (std::vector<std::string>{"####### .......",  //
                                                  "#.....# .......",  //
                                                  "#.##..# ..+.-..",  //
                                                  "#....?# .......",  //
                                                  "####### ......."}));
  EXPECT_EQ(w.added, 1);
  EXPECT_EQ(w.removed, 1);
}

TEST(MapChangesTest, MoveTakesTheWallsInItsBoxAlong) {
  // A box over the east wall moved one cell west: the wall cells in it move
  // into the room and leave free cells (a gap in the wall) behind.
  const ChangedWorld w = apply("move 6 2 7 4 -1 0\n");
  EXPECT_EQ(picture(w), (std::vector<std::string>{"####### .......",  //
                                                  "#....#. .....+-",  //
                                                  "#..###. .....+-",  //
                                                  "#....?# .......",  //
                                                  "####### ......."}));
  EXPECT_EQ(w.added, 2);
  EXPECT_EQ(w.removed, 2);
}

TEST(MapChangesTest, CommandsApplyInOrder) {
  // A cabinet added, then moved: only where it ends up is added; then the
  // table removed and a cabinet set where it stood: that cell is unchanged.
  const ChangedWorld w = apply(
      "add 1 1 2 2\n"
      "move 1 1 2 2 0 2\n"
      "remove 3 2 5 3\n"
      "add 3 2 4 3\n");
  EXPECT_EQ(picture(w), (std::vector<std::string>{"####### .......",  //
                                                  "##....# .+.....",  //
                                                  "#..#..# ....-..",  //
                                                  "#....?# .......",  //
                                                  "####### ......."}));
  EXPECT_EQ(w.added, 1);
  EXPECT_EQ(w.removed, 1);
}

TEST(MapChangesTest, AddDiscTakesTheCellsWithinItsRadius) {
  // On 0.1 m cells, a 0.2 m disc centred on a cell corner holds the 12
  // cells whose centres are within 0.2 m: 3 in each quadrant.
  const OccupancyGrid map = test::gridFromRows(std::vector<std::string>(8, "........"), 0.1);
  const ChangedWorld w = applyMapChanges(map, parse("add_disc 0.4 0.4 0.2\n"));
  EXPECT_EQ(picture(w), (std::vector<std::string>{"........ ........",  //
                                                  "........ ........",  //
                                                  "...##... ...++...",  //
                                                  "..####.. ..++++..",  //
                                                  "..####.. ..++++..",  //
                                                  "...##... ...++...",  //
                                                  "........ ........",  //
                                                  "........ ........"}));
  EXPECT_EQ(w.added, 12);
  EXPECT_EQ(w.map_occupied, 0);
  EXPECT_DOUBLE_EQ(w.changedShare(), 0.0);
}

TEST(MapChangesTest, ChangesThatDoNotFitTheMapNameTheLine) {
  const OccupancyGrid map = room();
  EXPECT_EQ(errorOf("add 1 1 2 2\nadd 6 1 8 2\n", &map),
            "test.changes:2: the box is not on the map");
  EXPECT_EQ(errorOf("\nremove 1 1 2 2\n", &map),
            "test.changes:2: no occupied cell in the box to remove");
  EXPECT_EQ(errorOf("move 1 1 3 2 1 0\n", &map),
            "test.changes:1: no occupied cell in the box to move");
  EXPECT_EQ(errorOf("move 3 2 5 3 0 3\n", &map), "test.changes:1: the moved box is not on the map");
  EXPECT_EQ(errorOf("move 3 2 5 3 0.4 0\n", &map),
            "test.changes:1: 'move' by less than half a cell moves nothing");
  // A box whose edges are the map's edges is on it.
  EXPECT_EQ(errorOf("remove 0 0 7 5\n", &map), "");
}

TEST(MapChangesTest, TheMaskGridIsTrinary) {
  const OccupancyGrid mask = apply("move 3 2 5 3 -1 0\n").maskGrid();
  EXPECT_EQ(mask.width(), 7);
  EXPECT_EQ(mask.height(), 5);
  EXPECT_DOUBLE_EQ(mask.resolution(), 1.0);
  EXPECT_EQ(mask.data()[mask.linearIndex({2, 2})], 100);  // added
  EXPECT_EQ(mask.data()[mask.linearIndex({4, 2})], -1);   // removed
  EXPECT_EQ(mask.data()[mask.linearIndex({3, 2})], 0);    // unchanged (occupied in both)
  EXPECT_EQ(mask.data()[mask.linearIndex({1, 1})], 0);    // unchanged (free in both)
}

TEST(MapChangesTest, LoadNamesAMissingFile) {
  EXPECT_THROW(loadMapChanges("/nonexistent/x.changes"), MapChangesError);
}

}  // namespace
}  // namespace pf::sim

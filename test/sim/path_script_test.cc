#include "pf_localization/sim/path_script.h"

#include <gtest/gtest.h>

#include <sstream>

#include "support/rooms.h"

namespace pf::sim {
namespace {

PathScript parse(const std::string& text) {
  std::istringstream in(text);
  return parsePathScript(in, "test.path");
}

// The message parsePathScript throws for `text`, or "" when it parses.
std::string errorOf(const std::string& text) {
  try {
    parse(text);
  } catch (const PathScriptError& e) {
    return e.what();
  }
  return "";
}

void expectMotion(const Motion& m, double v, double w, double duration, int line) {
  EXPECT_FALSE(m.teleport);
  EXPECT_DOUBLE_EQ(m.v, v);
  EXPECT_DOUBLE_EQ(m.w, w);
  EXPECT_DOUBLE_EQ(m.duration, duration);
  EXPECT_EQ(m.line, line);
}

TEST(PathScriptTest, CompilesEveryCommand) {
  const PathScript s = parse(
      "# a comment line\n"
      "\n"
      "start 1 2 0      # trailing comment\n"
      "speed 0.5 1.0\n"
      "goto 3 2\n"  // straight ahead: 2 m, no turn
      "goto 3 4\n"  // a quarter turn left, then 2 m
      "turn 0\n"
      "wait 1.5\n"
      "velocity 0.2 -0.1 3\n"
      "teleport 0 0 3.5\n"
      "person 0 0 1 0 0.5\n");
  EXPECT_EQ(s.file, "test.path");
  EXPECT_EQ(s.start_line, 3);
  EXPECT_DOUBLE_EQ(s.start.x, 1.0);
  EXPECT_DOUBLE_EQ(s.start.y, 2.0);
  ASSERT_EQ(s.motions.size(), 7u);
  expectMotion(s.motions[0], 0.5, 0.0, 4.0, 5);
  expectMotion(s.motions[1], 0.0, 1.0, M_PI / 2, 6);
  expectMotion(s.motions[2], 0.5, 0.0, 4.0, 6);
  expectMotion(s.motions[3], 0.0, -1.0, M_PI / 2, 7);
  expectMotion(s.motions[4], 0.0, 0.0, 1.5, 8);
  expectMotion(s.motions[5], 0.2, -0.1, 3.0, 9);
  EXPECT_TRUE(s.motions[6].teleport);
  EXPECT_DOUBLE_EQ(s.motions[6].target.yaw, 3.5 - 2 * M_PI);
  EXPECT_DOUBLE_EQ(s.duration(), 4.0 + M_PI / 2 + 4.0 + M_PI / 2 + 1.5 + 3.0);
  ASSERT_EQ(s.people.size(), 1u);
  EXPECT_DOUBLE_EQ(s.people[0].speed, 0.5);
}

TEST(PathScriptTest, GotoTakesTheShorterTurn) {
  const PathScript s = parse("start 0 0 3\ngoto -1 0\n");  // pi - 3 to the left
  ASSERT_EQ(s.motions.size(), 2u);
  EXPECT_DOUBLE_EQ(s.motions[0].w, 0.8);
  EXPECT_NEAR(s.motions[0].duration, (M_PI - 3.0) / 0.8, 1e-12);
}

TEST(PersonTest, WalksToAndFro) {
  const Person p{0.0, 0.0, 2.0, 0.0, 0.5};
  double x, y;
  p.positionAt(1.0, &x, &y);
  EXPECT_DOUBLE_EQ(x, 0.5);
  p.positionAt(5.0, &x, &y);  // 2.5 m walked: at the far end and half a metre back
  EXPECT_DOUBLE_EQ(x, 1.5);
  EXPECT_DOUBLE_EQ(y, 0.0);
}

TEST(PersonTest, StandsAtEachEndForItsPause) {
  const PathScript s = parse("person 0 0 2 0 0.5 3\nstart 0 0 0\n");
  ASSERT_EQ(s.people.size(), 1u);
  const Person& p = s.people[0];
  EXPECT_DOUBLE_EQ(p.pause, 3.0);
  double x, y;
  p.positionAt(2.0, &x, &y);  // 1 m out
  EXPECT_DOUBLE_EQ(x, 1.0);
  p.positionAt(4.5, &x, &y);  // standing at the far end (4 to 7 s)
  EXPECT_DOUBLE_EQ(x, 2.0);
  p.positionAt(9.0, &x, &y);  // 1 m back
  EXPECT_DOUBLE_EQ(x, 1.0);
  p.positionAt(13.0, &x, &y);  // standing at the near end (11 to 14 s)
  EXPECT_DOUBLE_EQ(x, 0.0);
  p.positionAt(16.0, &x, &y);  // out again
  EXPECT_DOUBLE_EQ(x, 1.0);
  EXPECT_DOUBLE_EQ(y, 0.0);
}

TEST(PathScriptTest, ErrorsNameFileAndLine) {
  EXPECT_EQ(errorOf("start 0 0 0\n\nfly 1 2\n"),
            "test.path:3: unknown command 'fly' (expected start, speed, goto, turn, wait, "
            "velocity, teleport, floor or person)");
  EXPECT_EQ(errorOf("start 0 0 0\ngoto 1 x\n"), "test.path:2: 'x' is not a number (in 'goto')");
  EXPECT_EQ(errorOf("start 0 0 0\ngoto 1 2e\n"), "test.path:2: '2e' is not a number (in 'goto')");
  EXPECT_EQ(errorOf("start 0 0 0\ngoto 1\n"), "test.path:2: 'goto' takes 2 number(s): goto x y");
  EXPECT_EQ(errorOf("start 0 0 0\nwait 1 2\n"),
            "test.path:2: 'wait' takes 1 number(s): wait seconds");
  EXPECT_EQ(errorOf("# nothing yet\ngoto 1 1\n"),
            "test.path:2: 'start x y yaw' must come before 'goto'");
  EXPECT_EQ(errorOf("start 0 0 0\nstart 1 1 0\n"), "test.path:2: 'start' given twice");
  EXPECT_EQ(errorOf("start 0 0 0\nspeed 0 1\n"),
            "test.path:2: speed v must be positive, got 0.000000");
  EXPECT_EQ(errorOf("start 0 0 0\nwait -1\n"),
            "test.path:2: wait time must be positive, got -1.000000");
  EXPECT_EQ(errorOf("start 0 0 nan\n"), "test.path:1: 'nan' is not a number (in 'start')");
  EXPECT_EQ(errorOf("# empty\n"), "test.path: no 'start x y yaw' line");
  EXPECT_THROW(loadPathScript("/nonexistent/x.path"), PathScriptError);
}

// A 10 x 6 room of 0.1 m cells (1 x 0.6 m) with a pillar in the middle.
OccupancyGrid room() { return pf::test::room(1.0, 0.6, 0.1, {{0.5, 0.2, 0.6, 0.4}}); }

TEST(CheckClearanceTest, AcceptsAPathInFreeSpace) {
  const PathScript s = parse("start 0.2 0.25 0\ngoto 0.2 0.35\nturn 3\nwait 1\n");
  EXPECT_EQ(checkClearance(s, room(), 0.045), std::nullopt);
}

TEST(CheckClearanceTest, ReportsTheLineThatHitsAWall) {
  const PathScript s = parse("start 0.2 0.25 0\nwait 1\ngoto 0.8 0.25\n");
  EXPECT_EQ(checkClearance(s, room(), 0.045).value_or(""),
            "test.path:3: the robot (radius 0.045 m) leaves free space at (0.46, 0.25)");
}

TEST(CheckClearanceTest, ChecksTheStartAndTeleportTargets) {
  EXPECT_EQ(checkClearance(parse("start 0.05 0.25 0\n"), room(), 0.045).value_or(""),
            "test.path:1: the robot (radius 0.045 m) leaves free space at (0.05, 0.25)");
  EXPECT_EQ(
      checkClearance(parse("start 0.2 0.25 0\nteleport 0.55 0.3 0\n"), room(), 0.045).value_or(""),
      "test.path:2: the robot (radius 0.045 m) leaves free space at (0.55, 0.30)");
}

// A lift ride: the path after `floor NAME` is checked on that floor's grid,
// and the player says which floor the robot is on.
TEST(CheckClearanceTest, ChecksEachFloorOnItsOwnGrid) {
  const OccupancyGrid open = pf::test::room(1.0, 0.6, 0.1, {});
  const PathScript s = parse("start 0.2 0.3 0\nwait 1\nfloor up\nwait 1\ngoto 0.8 0.3\n");
  ASSERT_EQ(4u, s.motions.size());  // wait, floor, wait, goto straight ahead
  EXPECT_EQ("up", s.motions[1].floor);
  EXPECT_DOUBLE_EQ(0.0, s.motions[1].duration);
  const auto floors = [&](const std::string& name) { return name == "up" ? &open : nullptr; };
  // On the ground floor's grid the goto would hit the pillar; upstairs it is clear.
  EXPECT_EQ(checkClearance(s, room(), 0.045, floors), std::nullopt);
  EXPECT_EQ(checkClearance(s, open, 0.045).value_or(""), "test.path:3: no floor 'up'");
  EXPECT_EQ(errorOf("start 0 0 0\nfloor\n"), "test.path:2: expected 'floor NAME'");

  DiffDriveRobot robot({}, s.start);
  PathPlayer player(s);
  player.advance(0.5, &robot, nullptr);
  EXPECT_EQ("", player.floor());
  player.advance(0.6, &robot, nullptr);
  EXPECT_EQ("up", player.floor());
  EXPECT_NEAR(robot.truePose().x, 0.2, 1e-12);  // the ride moves nothing
}

TEST(PathPlayerTest, StepSizeDoesNotChangeThePath) {
  const PathScript s = parse(
      "start 0 0 0\nteleport 1 0 0\nspeed 0.5 1\ngoto 2 0\nteleport 5 5 0\ngoto 6 5\nturn 1\n");
  for (double dt : {0.03, 0.01, 1.0, 100.0}) {
    DiffDriveRobot robot({}, s.start);
    PathPlayer player(s);
    player.advance(0.0, &robot, nullptr);  // the teleport at t = 0
    EXPECT_DOUBLE_EQ(robot.truePose().x, 1.0);
    while (!player.finished()) player.advance(dt, &robot, nullptr);
    EXPECT_NEAR(robot.truePose().x, 6.0, 1e-9) << "dt " << dt;
    EXPECT_NEAR(robot.truePose().y, 5.0, 1e-9) << "dt " << dt;
    EXPECT_NEAR(robot.truePose().yaw, 1.0, 1e-9) << "dt " << dt;
    // The wheels turned for 2 m and 1 rad, wherever the robot was carried.
    EXPECT_NEAR(robot.odomPose().x, 2.0, 1e-9) << "dt " << dt;
    EXPECT_NEAR(robot.odomPose().yaw, 1.0, 1e-9) << "dt " << dt;
  }
}

}  // namespace
}  // namespace pf::sim

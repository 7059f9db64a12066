// The path scripts that tell pf_simulator where the robot drives.
//
// A script is plain text, one command per line; '#' starts a comment, blank
// lines are ignored. Lengths are metres, angles radians, times seconds, all in
// the map frame:
//
//   start x y yaw          where the robot is at t = 0 (required, first, once)
//   speed v w              linear (m/s) and turning (rad/s) speed used by goto
//                          and turn from here on; default 0.25 and 0.8
//   goto x y               turn in place towards (x, y), then drive straight there
//   turn yaw               turn in place to the absolute heading yaw
//   wait t                 stand still for t seconds
//   velocity v w t         drive at v m/s turning at w rad/s for t seconds (an arc)
//   teleport x y yaw       move the true pose instantly, wheels still (a kidnapping)
//   floor NAME             from here on the robot is on floor NAME of the building
//                          (a lift ride: wait in the lift before and after it);
//                          the world the sensors see is that floor's map
//   person x1 y1 x2 y2 v [pause]
//                          a person (seen as a 0.2 m radius circle) walking to
//                          and fro between two points at v m/s, for the whole
//                          run, standing `pause` s at each end (default 0);
//                          people are not on the map and may cross the robot
//
// A script compiles to a list of constant-velocity motions. The true pose
// follows them exactly, so whether the robot stays in free space can be
// checked on the map before anything is simulated (checkClearance).
#pragma once

#include <functional>
#include <istream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/util/pose2.h"
#include "pf_localization/sim/diff_drive_robot.h"
#include "pf_localization/sim/sim_random.h"

namespace pf::sim {

/// A malformed script. what() is "file:line: message".
class PathScriptError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One compiled step: drive at (v, w) for `duration`, or teleport to `target`.
struct Motion {
  bool teleport = false;
  double v = 0.0;         // m/s
  double w = 0.0;         // rad/s
  double duration = 0.0;  // s
  Pose2 target;           // teleports only
  int line = 0;           // script line that produced it
  std::string floor;      // non-empty: no motion, the robot is now on this floor
};

/// A circular obstacle that is not on the map, walking back and forth.
struct Person {
  double x1 = 0.0, y1 = 0.0, x2 = 0.0, y2 = 0.0;  // m
  double speed = 0.0;                             // m/s
  double radius = 0.2;                            // m
  double pause = 0.0;                             // s standing at each end before turning back
  /// Centre at time t (s): a triangle wave between the two end points,
  /// flat for `pause` at each end (a person lingering there).
  void positionAt(double t, double* x, double* y) const;
};

struct PathScript {
  std::string file;  // for error messages
  Pose2 start;
  int start_line = 0;
  std::vector<Motion> motions;
  std::vector<Person> people;

  /// Total duration of the motions (s).
  double duration() const;
};

/// Parses a script; `file` only names it in errors. Throws PathScriptError
/// for an unknown command, a wrong argument count, a bad number, a
/// non-positive speed or duration, or a missing or repeated `start`.
PathScript parsePathScript(std::istream& in, const std::string& file);

/// Reads and parses a script file. Throws PathScriptError (also when the file
/// cannot be opened).
PathScript loadPathScript(const std::string& path);

/// Checks that a robot of `radius` metres stays in free cells of `grid` along
/// the whole true path (sampled every 1 cm), teleport targets included.
/// Returns "file:line: ..." naming the first motion that leaves free space.
/// After a `floor NAME` the path is checked on `floor_grid(NAME)`, which
/// is null for a floor that does not exist (also when floor_grid is empty).
std::optional<std::string> checkClearance(
    const PathScript& script, const OccupancyGrid& grid, double radius,
    const std::function<const OccupancyGrid*(const std::string&)>& floor_grid = {});

/// Plays a script's motions on a robot in steps of any length: a step that
/// spans the end of one motion finishes it and goes on with the next, so the
/// true path does not depend on the step size.
class PathPlayer {
 public:
  /// `script` must outlive the player.
  explicit PathPlayer(const PathScript& script);

  /// Drives `robot` through the next dt seconds of the script, teleports
  /// included (advance(0) performs those due at the current time). After the
  /// end the robot stands still.
  void advance(double dt, DiffDriveRobot* robot, SimRandom* random);
  bool finished() const { return next_ >= script_.motions.size(); }
  /// The floor of the last `floor NAME` played; empty before any.
  const std::string& floor() const { return floor_; }

 private:
  const PathScript& script_;
  std::size_t next_ = 0;  // the motion under way
  double left_ = 0.0;     // seconds left of it
  std::string floor_;
};

}  // namespace pf::sim

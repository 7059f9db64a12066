#include "pf_localization/sim/path_script.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "pf_localization/sim/line_parser.h"

namespace pf::sim {

void Person::positionAt(double t, double* x, double* y) const {
  const double length = std::hypot(x2 - x1, y2 - y1);
  double s = 0.0;
  if (length > 0.0 && speed > 0.0 && pause > 0.0) {
    const double leg = length / speed;
    const double u = std::fmod(t, 2.0 * (leg + pause));  // out, stand, back, stand
    s = u < leg                 ? u / leg
        : u < leg + pause       ? 1.0
        : u < 2.0 * leg + pause ? 1.0 - (u - leg - pause) / leg
                                : 0.0;
  } else if (length > 0.0 && speed > 0.0) {
    s = std::fmod(speed * t, 2.0 * length);
    if (s > length) s = 2.0 * length - s;  // on the way back
    s /= length;
  }
  *x = x1 + s * (x2 - x1);
  *y = y1 + s * (y2 - y1);
}

double PathScript::duration() const {
  double total = 0.0;
  for (const Motion& m : motions) total += m.duration;
  return total;
}

namespace {

// `person x1 y1 x2 y2 v [pause]`, a line of `words` words.
Person parsePerson(const LineParser<PathScriptError>& p, std::size_t words) {
  const auto a = p.numbers(words == 7 ? 6 : 5, "person x1 y1 x2 y2 speed [pause]");
  if (a[4] < 0.0) p.fail("person speed must not be negative");
  if (a.back() < 0.0) p.fail("person pause must not be negative");
  Person person{a[0], a[1], a[2], a[3], a[4]};
  if (a.size() == 6) person.pause = a[5];
  return person;
}

}  // namespace

PathScript parsePathScript(std::istream& in, const std::string& file) {
  PathScript script;
  script.file = file;
  bool started = false;
  double speed_v = 0.25, speed_w = 0.8;
  Pose2 pose;  // where the robot will be after the motions so far

  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    const std::vector<std::string> words = scriptWords(text);
    if (words.empty()) continue;

    const LineParser<PathScriptError> p(file, line, words);
    const std::string& cmd = p.command();
    if (!started && cmd != "start" && cmd != "person") {
      p.fail("'start x y yaw' must come before '" + cmd + "'");
    }
    const auto drive = [&](double v, double w, double duration) {
      if (duration <= 0.0) return;
      script.motions.push_back({false, v, w, duration, {}, line, {}});
      pose = integrateArc(pose, v * duration, w * duration);
    };
    const auto turnBy = [&](double angle) {
      drive(0.0, std::copysign(speed_w, angle), std::abs(angle) / speed_w);
    };

    if (cmd == "start") {
      if (started) p.fail("'start' given twice");
      const auto a = p.numbers(3, "start x y yaw");
      script.start = pose = {a[0], a[1], normalizeAngle(a[2])};
      script.start_line = line;
      started = true;
    } else if (cmd == "speed") {
      const auto a = p.numbers(2, "speed v w");
      p.requirePositive(a[0], "speed v");
      p.requirePositive(a[1], "speed w");
      speed_v = a[0];
      speed_w = a[1];
    } else if (cmd == "goto") {
      const auto a = p.numbers(2, "goto x y");
      const double dx = a[0] - pose.x, dy = a[1] - pose.y;
      const double distance = std::hypot(dx, dy);
      if (distance > 1e-9) {
        const double heading = std::atan2(dy, dx);
        turnBy(angleDiff(heading, pose.yaw));
        drive(speed_v, 0.0, distance / speed_v);
        // Land exactly on the target, so rounding never builds up over a long script.
        pose = {a[0], a[1], heading};
      }
    } else if (cmd == "turn") {
      const auto a = p.numbers(1, "turn yaw");
      const double target = normalizeAngle(a[0]);
      turnBy(angleDiff(target, pose.yaw));
      pose.yaw = target;
    } else if (cmd == "wait") {
      const auto a = p.numbers(1, "wait seconds");
      p.requirePositive(a[0], "wait time");
      drive(0.0, 0.0, a[0]);
    } else if (cmd == "velocity") {
      const auto a = p.numbers(3, "velocity v w seconds");
      p.requirePositive(a[2], "velocity duration");
      drive(a[0], a[1], a[2]);
    } else if (cmd == "teleport") {
      const auto a = p.numbers(3, "teleport x y yaw");
      pose = {a[0], a[1], normalizeAngle(a[2])};
      script.motions.push_back({true, 0.0, 0.0, 0.0, pose, line, {}});
    } else if (cmd == "floor") {
      script.motions.push_back({false, 0.0, 0.0, 0.0, {}, line, p.word("floor NAME")});
    } else if (cmd == "person") {
      script.people.push_back(parsePerson(p, words.size()));
    } else {
      p.fail("unknown command '" + cmd +
             "' (expected start, speed, goto, turn, wait, velocity, teleport, floor or person)");
    }
  }
  if (!started) throw PathScriptError(file + ": no 'start x y yaw' line");
  return script;
}

PathScript loadPathScript(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PathScriptError(path + ": cannot open");
  return parsePathScript(in, path);
}

namespace {

// True when every cell that a disc of `radius` at (x, y) touches is free.
bool footprintFree(const OccupancyGrid& grid, double x, double y, double radius) {
  const double half = 0.5 * grid.resolution();
  const int reach = static_cast<int>(std::ceil(radius / grid.resolution())) + 1;
  const CellIndex c = grid.worldToCell(x, y);
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const CellIndex n{c.x + dx, c.y + dy};
      double cx, cy;
      grid.cellToWorld(n, &cx, &cy);
      // Distance from the disc's centre to the nearest point of the cell.
      const double gap_x = std::max(0.0, std::abs(cx - x) - half);
      const double gap_y = std::max(0.0, std::abs(cy - y) - half);
      if (std::hypot(gap_x, gap_y) >= radius) continue;
      if (grid.state(n) != CellState::kFree) return false;
    }
  }
  return true;
}

}  // namespace

std::optional<std::string> checkClearance(
    const PathScript& script, const OccupancyGrid& grid, double radius,
    const std::function<const OccupancyGrid*(const std::string&)>& floor_grid) {
  constexpr double kSampleStep = 0.01;  // m
  const auto blocked = [&](int line, const Pose2& at) {
    char message[128];
    std::snprintf(message, sizeof(message),
                  ":%d: the robot (radius %g m) leaves free space at (%.2f, %.2f)", line, radius,
                  at.x, at.y);
    return script.file + message;
  };
  Pose2 pose = script.start;
  const OccupancyGrid* on = &grid;
  if (!footprintFree(*on, pose.x, pose.y, radius)) return blocked(script.start_line, pose);
  for (const Motion& m : script.motions) {
    if (!m.floor.empty()) {
      on = floor_grid ? floor_grid(m.floor) : nullptr;
      if (!on) return script.file + ":" + std::to_string(m.line) + ": no floor '" + m.floor + "'";
      if (!footprintFree(*on, pose.x, pose.y, radius)) return blocked(m.line, pose);
      continue;
    }
    if (m.teleport) {
      pose = m.target;
      if (!footprintFree(*on, pose.x, pose.y, radius)) return blocked(m.line, pose);
      continue;
    }
    const double length = std::abs(m.v) * m.duration;
    const int samples = std::max(1, static_cast<int>(std::ceil(length / kSampleStep)));
    for (int i = 1; i <= samples; ++i) {
      const double t = m.duration * i / samples;
      const Pose2 at = integrateArc(pose, m.v * t, m.w * t);
      if (!footprintFree(*on, at.x, at.y, radius)) return blocked(m.line, at);
    }
    pose = integrateArc(pose, m.v * m.duration, m.w * m.duration);
  }
  return std::nullopt;
}

PathPlayer::PathPlayer(const PathScript& script) : script_(script) {
  if (!finished()) left_ = script_.motions[0].duration;
}

void PathPlayer::advance(double dt, DiffDriveRobot* robot, SimRandom* random) {
  // Times below a picosecond are rounding noise from splitting steps.
  constexpr double kEps = 1e-12;
  while (!finished() &&
         (dt > kEps || script_.motions[next_].teleport || !script_.motions[next_].floor.empty())) {
    const Motion& m = script_.motions[next_];
    if (!m.floor.empty()) {
      floor_ = m.floor;
    } else if (m.teleport) {
      robot->teleport(m.target);
    } else {
      const double h = std::min(dt, left_);
      robot->step(m.v, m.w, h, random);
      dt -= h;
      left_ -= h;
      if (left_ > kEps) continue;
    }
    if (++next_ < script_.motions.size()) left_ = script_.motions[next_].duration;
  }
  if (dt > kEps) robot->step(0.0, 0.0, dt, random);
}

}  // namespace pf::sim

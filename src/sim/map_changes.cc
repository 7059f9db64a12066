#include "pf_localization/sim/map_changes.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "pf_localization/sim/line_parser.h"

namespace pf::sim {

namespace {

using Kind = MapChange::Kind;

constexpr int8_t kFreeValue = 0;
constexpr int8_t kOccupiedValue = 100;

// The box of a line's four numbers, which must not be empty.
Box boxOf(const LineParser<MapChangesError>& p, const std::vector<double>& a) {
  if (!(a[0] < a[2]) || !(a[1] < a[3])) {
    p.fail("the box must have x0 < x1 and y0 < y1 (in '" + p.command() + "')");
  }
  return {a[0], a[1], a[2], a[3]};
}

MapChange parseLine(const LineParser<MapChangesError>& p, int line) {
  const std::string& cmd = p.command();
  MapChange c;
  c.line = line;
  if (cmd == "add") {
    c.kind = Kind::kAdd;
    c.box = boxOf(p, p.numbers(4, "add x0 y0 x1 y1"));
  } else if (cmd == "add_disc") {
    const auto a = p.numbers(3, "add_disc x y r");
    p.requirePositive(a[2], "the radius");
    c.kind = Kind::kAddDisc;
    c.box = {a[0] - a[2], a[1] - a[2], a[0] + a[2], a[1] + a[2]};
  } else if (cmd == "remove") {
    c.kind = Kind::kRemove;
    c.box = boxOf(p, p.numbers(4, "remove x0 y0 x1 y1"));
  } else if (cmd == "move") {
    const auto a = p.numbers(6, "move x0 y0 x1 y1 dx dy");
    c.kind = Kind::kMove;
    c.box = boxOf(p, a);
    c.dx = a[4];
    c.dy = a[5];
    if (c.dx == 0.0 && c.dy == 0.0) p.fail("'move' by (0, 0) moves nothing");
  } else {
    p.fail("unknown command '" + cmd + "' (expected add, add_disc, remove or move)");
  }
  return c;
}

}  // namespace

std::vector<int> cellsInBox(const OccupancyGrid& map, const Box& b) {
  double lo_x = map.width(), lo_y = map.height(), hi_x = 0.0, hi_y = 0.0;
  for (double x : {b.x0, b.x1}) {
    for (double y : {b.y0, b.y1}) {
      const Pose2 p = between(map.origin(), {x, y, 0.0});
      lo_x = std::min(lo_x, p.x / map.resolution());
      hi_x = std::max(hi_x, p.x / map.resolution());
      lo_y = std::min(lo_y, p.y / map.resolution());
      hi_y = std::max(hi_y, p.y / map.resolution());
    }
  }
  std::vector<int> cells;
  for (int j = std::max(0, static_cast<int>(lo_y) - 1);
       j <= std::min(map.height() - 1, static_cast<int>(hi_y) + 1); ++j) {
    for (int i = std::max(0, static_cast<int>(lo_x) - 1);
         i <= std::min(map.width() - 1, static_cast<int>(hi_x) + 1); ++i) {
      double x, y;
      map.cellToWorld({i, j}, &x, &y);
      if (x < b.x0 || x > b.x1 || y < b.y0 || y > b.y1) continue;
      cells.push_back(map.linearIndex({i, j}));
    }
  }
  return cells;
}

namespace {

// A map's cells under change: the world's values on the map's geometry.
class WorldCanvas {
 public:
  WorldCanvas(const OccupancyGrid& map, const std::string& file)
      : map_(map), file_(file), data_(map.data()) {}

  void apply(const MapChange& c) {
    requireOnMap(c, c.box, 0.0, 0.0);
    std::vector<int> cells = cellsIn(c);
    if (c.kind == Kind::kAdd || c.kind == Kind::kAddDisc) {
      for (int i : cells) data_[i] = kOccupiedValue;
      return;
    }
    cells.erase(std::remove_if(cells.begin(), cells.end(),
                               [&](int i) {
                                 return OccupancyGrid::classify(data_[i]) != CellState::kOccupied;
                               }),
                cells.end());
    if (cells.empty()) fail(c, "no occupied cell in the box to " + commandName(c));
    if (c.kind == Kind::kRemove) {
      for (int i : cells) data_[i] = kFreeValue;
    } else {
      move(c, cells);
    }
  }

  const std::vector<int8_t>& data() const { return data_; }

 private:
  [[noreturn]] void fail(const MapChange& c, const std::string& message) const {
    throw MapChangesError(file_ + ":" + std::to_string(c.line) + ": " + message);
  }

  static std::string commandName(const MapChange& c) {
    return c.kind == Kind::kRemove ? "remove" : "move";
  }

  // (x, y) in the grid's own frame, metres from its lower-left corner.
  Pose2 local(double x, double y) const { return between(map_.origin(), {x, y, 0.0}); }

  // Throws unless `box`, shifted by (sx, sy) in the grid's frame, is on the map.
  void requireOnMap(const MapChange& c, const Box& box, double sx, double sy) const {
    constexpr double kSlack = 1e-9;  // a box edge on the map's edge is on it
    const double w = map_.width() * map_.resolution(), h = map_.height() * map_.resolution();
    for (double x : {box.x0, box.x1}) {
      for (double y : {box.y0, box.y1}) {
        const Pose2 p = local(x, y);
        const double lx = p.x + sx, ly = p.y + sy;
        if (lx < -kSlack || ly < -kSlack || lx > w + kSlack || ly > h + kSlack) {
          fail(c, sx == 0.0 && sy == 0.0 ? "the box is not on the map"
                                         : "the moved box is not on the map");
        }
      }
    }
  }

  // The cells whose centres are inside the change's box (its disc).
  std::vector<int> cellsIn(const MapChange& c) const {
    std::vector<int> cells = cellsInBox(map_, c.box);
    if (c.kind != Kind::kAddDisc) return cells;
    const Box& b = c.box;
    const double cx = 0.5 * (b.x0 + b.x1), cy = 0.5 * (b.y0 + b.y1), r = 0.5 * (b.x1 - b.x0);
    cells.erase(std::remove_if(cells.begin(), cells.end(),
                               [&](int i) {
                                 double x, y;
                                 map_.cellToWorld({i % map_.width(), i / map_.width()}, &x, &y);
                                 return std::hypot(x - cx, y - cy) > r;
                               }),
                cells.end());
    return cells;
  }

  // Moves the occupied `cells` by the change's shift, rounded to whole cells
  // of the grid's frame.
  void move(const MapChange& c, const std::vector<int>& cells) {
    const double yaw = map_.origin().yaw;
    const double gx = std::cos(yaw) * c.dx + std::sin(yaw) * c.dy;
    const double gy = -std::sin(yaw) * c.dx + std::cos(yaw) * c.dy;
    const int di = static_cast<int>(std::lround(gx / map_.resolution()));
    const int dj = static_cast<int>(std::lround(gy / map_.resolution()));
    if (di == 0 && dj == 0) fail(c, "'move' by less than half a cell moves nothing");
    requireOnMap(c, c.box, di * map_.resolution(), dj * map_.resolution());
    std::vector<int8_t> values;
    for (int i : cells) {
      values.push_back(data_[i]);
      data_[i] = kFreeValue;
    }
    for (std::size_t k = 0; k < cells.size(); ++k) {
      data_[cells[k] + dj * map_.width() + di] = values[k];
    }
  }

  const OccupancyGrid& map_;
  const std::string& file_;
  std::vector<int8_t> data_;
};

}  // namespace

MapChanges parseMapChanges(std::istream& in, const std::string& file) {
  MapChanges out;
  out.file = file;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    const std::vector<std::string> words = scriptWords(text);
    if (words.empty()) continue;
    out.changes.push_back(parseLine(LineParser<MapChangesError>(file, line, words), line));
  }
  return out;
}

MapChanges loadMapChanges(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw MapChangesError(path + ": cannot open");
  return parseMapChanges(in, path);
}

double ChangedWorld::changedShare() const {
  return map_occupied > 0 ? static_cast<double>(added + removed) / map_occupied : 0.0;
}

OccupancyGrid ChangedWorld::maskGrid() const {
  std::vector<int8_t> values(mask.size(), 0);
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (mask[i] == CellChange::kAdded) values[i] = 100;
    if (mask[i] == CellChange::kRemoved) values[i] = -1;
  }
  return OccupancyGrid(world.width(), world.height(), world.resolution(), world.origin(),
                       std::move(values));
}

ChangedWorld applyMapChanges(const OccupancyGrid& map, const MapChanges& changes) {
  WorldCanvas canvas(map, changes.file);
  for (const MapChange& c : changes.changes) canvas.apply(c);
  ChangedWorld out;
  out.world =
      OccupancyGrid(map.width(), map.height(), map.resolution(), map.origin(), canvas.data());
  out.mask.assign(map.data().size(), CellChange::kUnchanged);
  for (std::size_t i = 0; i < out.mask.size(); ++i) {
    const bool before = OccupancyGrid::classify(map.data()[i]) == CellState::kOccupied;
    const bool after = OccupancyGrid::classify(canvas.data()[i]) == CellState::kOccupied;
    out.map_occupied += before;
    if (after && !before) {
      out.mask[i] = CellChange::kAdded;
      ++out.added;
    } else if (before && !after) {
      out.mask[i] = CellChange::kRemoved;
      ++out.removed;
    }
  }
  return out;
}

}  // namespace pf::sim

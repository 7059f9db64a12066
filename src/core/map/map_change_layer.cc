#include "pf_localization/core/map/map_change_layer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pf_localization/core/motion/scan_deskew.h"

namespace pf {
namespace {

void bump(std::uint16_t* n) {
  if (*n < std::numeric_limits<std::uint16_t>::max()) ++*n;
}

}  // namespace

std::size_t MapChangeLayer::tileOf(std::size_t i, std::size_t* in_tile) const {
  const std::size_t w = static_cast<std::size_t>(width_);
  const std::size_t x = i % w, y = i / w;
  *in_tile = ((y & (kTileSize - 1)) << kTileBits) | (x & (kTileSize - 1));
  return (y >> kTileBits) * static_cast<std::size_t>(tiles_x_) + (x >> kTileBits);
}

MapChangeLayer::Counts& MapChangeLayer::countsAt(std::size_t i) {
  std::size_t in_tile;
  std::unique_ptr<Counts[]>& tile = tiles_[tileOf(i, &in_tile)];
  if (!tile) tile = std::make_unique<Counts[]>(kTileSize * kTileSize);
  return tile[in_tile];
}

const MapChangeLayer::Counts& MapChangeLayer::countsAt(std::size_t i) const {
  static const Counts kNone;
  std::size_t in_tile;
  const std::unique_ptr<Counts[]>& tile = tiles_[tileOf(i, &in_tile)];
  return tile ? tile[in_tile] : kNone;
}

void MapChangeLayer::count(std::size_t i, Kind kind) {
  Counts& c = countsAt(i);
  const auto scan = static_cast<std::uint16_t>(scans_);
  if (c.scan != scan) {
    c.scan = scan;
    c.counted = 0;
  }
  if (c.counted & kind) return;
  c.counted |= kind;
  switch (kind) {
    case kHit:
      bump(&c.hits);
      break;
    case kFree:
      bump(&c.free);
      break;
    case kPass:
      bump(&c.passes);
      break;
    case kEnd:
      bump(&c.ends);
      break;
  }
  show(i, classify(i));
}

void MapChangeLayer::show(std::size_t i, Cell c) {
  const Cell was = shown(i);
  if (c == was) return;
  // Unseen counts nowhere; every other state once in seen.
  if (was == Cell::kUnseen) ++summary_.seen;
  if (c == Cell::kUnseen) --summary_.seen;
  if (was == Cell::kAdded) --summary_.added;
  if (c == Cell::kAdded) ++summary_.added;
  if (was == Cell::kRemoved) --summary_.removed;
  if (c == Cell::kRemoved) ++summary_.removed;
  cells_[i] = static_cast<std::uint8_t>((cells_[i] & ~kShownBits) | static_cast<std::uint8_t>(c)
                                                                        << kShownShift);
  if (removed(i) || added(i) || was == Cell::kAdded || was == Cell::kRemoved) {
    changed_cells_.push_back(i);
  }
}

std::vector<std::int8_t> MapChangeLayer::occupancy() const {
  std::vector<std::int8_t> out(cells_.size());
  for (std::size_t i = 0; i < cells_.size(); ++i) out[i] = valueOf(shown(i));
  return out;
}

std::vector<std::size_t> MapChangeLayer::takeChangedCells() {
  std::vector<std::size_t> out;
  out.swap(changed_cells_);
  return out;
}

void MapChangeLayer::see(std::size_t i) {
  if (cells_[i] & kSeen) return;
  cells_[i] |= kSeen;
  show(i, Cell::kAsMapped);
}

MapChangeLayer::MapChangeLayer(const DistanceField& field)
    : width_(field.grid().width()),
      height_(field.grid().height()),
      frame_(field.grid()),
      tiles_x_((width_ + kTileSize - 1) >> kTileBits) {
  const OccupancyGrid& grid = field.grid();
  cells_.resize(grid.data().size());
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    switch (OccupancyGrid::classify(grid.data()[i])) {
      case CellState::kOccupied:
        cells_[i] = kMapOccupied;
        break;
      case CellState::kUnknown:
        cells_[i] = kMapUnknown;
        break;
      case CellState::kFree:
        cells_[i] = field.distance(i) <= kBesideObstacle ? kMapBeside : kMapFree;
        break;
    }
  }
  tiles_.resize(static_cast<std::size_t>(tiles_x_) * ((height_ + kTileSize - 1) >> kTileBits));
}

void MapChangeLayer::clear() {
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    if (removed(i) || added(i)) changed_cells_.push_back(i);
  }
  for (std::unique_ptr<Counts[]>& tile : tiles_) tile.reset();
  for (std::uint8_t& c : cells_) c &= kMapBits;  // unseen, shown as such (0)
  summary_ = Summary();
  scans_ = 0;
}

bool MapChangeLayer::wants(const Pose2& robot) const {
  return scans_ == 0 || std::hypot(robot.x - last_.x, robot.y - last_.y) >= kMinStep ||
         std::abs(normalizeAngle(robot.yaw - last_.yaw)) >= kMinTurn;
}

void MapChangeLayer::add(const ScanGroup& scans, const Pose2& robot) {
  for (const LaserScan& scan : scans) {
    const std::size_t n = scan.ranges.size();
    const Pose2 base = compose(robot, scan.robot_offset);
    const bool skewed = !scan.sweep.isStill();
    const std::size_t stride = std::max<std::size_t>(1, n / kRaysPerScan);
    Pose2 sensor = compose(base, scan.sensor_pose);
    double x, y;  // the sensor in cells of the grid's frame
    frame_.pointInCells(sensor.x, sensor.y, &x, &y);
    for (std::size_t i = 0; i < n; i += stride) {
      if (!isReading(scan.ranges[i], scan.range_min, scan.range_max)) continue;
      if (skewed) {
        sensor = compose(base, sensorPoseAtBeam(scan.sensor_pose, scan.sweep, i));
        frame_.pointInCells(sensor.x, sensor.y, &x, &y);
      }
      const double angle = sensor.yaw - frame_.yaw() + scan.angle_min +
                           static_cast<double>(i) * scan.angle_increment;
      walk(x, y, std::cos(angle), std::sin(angle), scan.ranges[i]);
    }
  }
  ++scans_;
  last_ = robot;
}

void MapChangeLayer::walk(double x, double y, double ux, double uy, double range) {
  const double length = (std::min(range, kMaxRange) - kEndMargin) * frame_.cellsPerMetre();
  int cx = static_cast<int>(std::floor(x)), cy = static_cast<int>(std::floor(y));
  const int step_x = ux >= 0.0 ? 1 : -1, step_y = uy >= 0.0 ? 1 : -1;
  const double inf = std::numeric_limits<double>::infinity();
  const double delta_x = ux != 0.0 ? std::abs(1.0 / ux) : inf;
  const double delta_y = uy != 0.0 ? std::abs(1.0 / uy) : inf;
  double next_x = ux != 0.0 ? (cx + (step_x > 0 ? 1 : 0) - x) / ux : inf;
  double next_y = uy != 0.0 ? (cy + (step_y > 0 ? 1 : 0) - y) / uy : inf;
  double t = 0.0;
  while (t <= length && cx >= 0 && cy >= 0 && cx < width_ && cy < height_) {
    // Most cells are free, and only their byte is touched.
    const std::size_t i = static_cast<std::size_t>(cy) * width_ + cx;
    std::uint8_t& cell = cells_[i];
    const std::uint8_t map = cell & kMapBits;
    if (map != kMapUnknown) {
      see(i);
      if (map == kMapOccupied) {
        count(i, kPass);
      } else if (cell & kWasHit) {
        count(i, kFree);
      }
    }
    if (next_x < next_y) {
      t = next_x;
      next_x += delta_x;
      cx += step_x;
    } else {
      t = next_y;
      next_y += delta_y;
      cy += step_y;
    }
  }
  if (range <= kMaxRange) {
    end(x + ux * range * frame_.cellsPerMetre(), y + uy * range * frame_.cellsPerMetre());
  }
}

void MapChangeLayer::end(double x, double y) {
  const int cx = static_cast<int>(std::floor(x)), cy = static_cast<int>(std::floor(y));
  if (cx < 0 || cy < 0 || cx >= width_ || cy >= height_) return;
  const std::size_t i = static_cast<std::size_t>(cy) * width_ + cx;
  if ((cells_[i] & kMapBits) == kMapFree) {
    see(i);
    cells_[i] |= kWasHit;
    count(i, kHit);
    return;
  }
  // On (or beside) the map's obstacle: an end for each mapped obstacle cell
  // around the end point.
  for (int ny = std::max(0, cy - 1); ny <= std::min(height_ - 1, cy + 1); ++ny) {
    for (int nx = std::max(0, cx - 1); nx <= std::min(width_ - 1, cx + 1); ++nx) {
      const std::size_t j = static_cast<std::size_t>(ny) * width_ + nx;
      if ((cells_[j] & kMapBits) != kMapOccupied) continue;
      see(j);
      count(j, kEnd);
    }
  }
}

MapChangeLayer::Cell MapChangeLayer::classify(std::size_t i) const {
  if (!(cells_[i] & kSeen)) return Cell::kUnseen;
  const Counts& c = countsAt(i);
  const int hits = c.hits, passes = c.passes;
  const int stopped = hits + c.free, reached = passes + c.ends;
  if (hits >= kMinScans && hits >= kChangedShare * stopped) return Cell::kAdded;
  if (passes >= kMinScans && passes >= kChangedShare * reached) return Cell::kRemoved;
  return Cell::kAsMapped;
}

std::int8_t MapChangeLayer::valueOf(Cell c) {
  switch (c) {
    case Cell::kUnseen:
      return -1;
    case Cell::kAsMapped:
      return 0;
    case Cell::kAdded:
      return 100;
    case Cell::kRemoved:
      return 50;
  }
  return -1;
}

std::vector<std::uint8_t> MapChangeLayer::pixels() const {
  std::vector<std::uint8_t> out(cells_.size());
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const Cell c = shown(i);
    out[i] = c == Cell::kAdded ? 0 : c == Cell::kRemoved ? 205 : c == Cell::kAsMapped ? 254 : 128;
  }
  return out;
}

}  // namespace pf

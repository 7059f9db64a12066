#include "pf_localization/core/map/map_change_layer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "pf_localization/core/motion/scan_deskew.h"

namespace pf {
namespace {

void bump(std::uint16_t* n) {
  if (*n < std::numeric_limits<std::uint16_t>::max()) ++*n;
}

// encode()'s numbers: unsigned integers in 7-bit groups, the lowest first
// (LEB128), doubles as their 8 bytes, the lowest first.
void putNumber(std::string* out, std::uint64_t v) {
  for (; v >= 0x80; v >>= 7) out->push_back(static_cast<char>(v | 0x80));
  out->push_back(static_cast<char>(v));
}

void putReal(std::string* out, double d) {
  std::uint64_t bits;
  std::memcpy(&bits, &d, sizeof bits);
  for (int k = 0; k < 8; ++k) out->push_back(static_cast<char>(bits >> (8 * k) & 0xff));
}

// A place's coordinate as an unsigned number, small for small magnitudes
// (protocol buffers' zigzag), and back.
std::uint64_t zigzag(std::int16_t v) {
  return static_cast<std::uint64_t>(v < 0 ? -2 * static_cast<int>(v) - 1 : 2 * static_cast<int>(v));
}

std::int16_t unzigzag(std::uint64_t u) {
  return static_cast<std::int16_t>(u & 1 ? -static_cast<int>((u + 1) / 2)
                                         : static_cast<int>(u / 2));
}

// Reads what putNumber and putReal wrote; past the end, or a number longer
// than 64 bits, it stops being ok() and gives zeros.
class ByteReader {
 public:
  explicit ByteReader(const std::string& bytes) : bytes_(bytes) {}
  bool ok() const { return ok_; }
  bool atEnd() const { return pos_ == bytes_.size(); }
  std::uint8_t byte() {
    if (pos_ >= bytes_.size()) ok_ = false;
    return ok_ ? static_cast<std::uint8_t>(bytes_[pos_++]) : 0;
  }
  std::uint64_t number() {
    std::uint64_t v = 0;
    for (int shift = 0; shift < 64 && ok_; shift += 7) {
      const std::uint8_t b = byte();
      v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) return ok_ ? v : 0;
    }
    ok_ = false;
    return 0;
  }
  double real() {
    std::uint64_t bits = 0;
    for (int k = 0; k < 8; ++k) bits |= static_cast<std::uint64_t>(byte()) << (8 * k);
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return ok_ ? d : 0.0;
  }

 private:
  const std::string& bytes_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

// A cell's counts as encode() writes them, after the cell's index: hits,
// free, passes, ends, clear, apart | moved_in << 1, hit_x and hit_y
// zigzagged; into *c when they are ones the layer gives.
template <class Counts>
bool fillCounts(const std::uint64_t (&v)[8], Counts* c) {
  if (*std::max_element(v, v + 4) > std::numeric_limits<std::uint16_t>::max() ||
      v[4] > std::numeric_limits<std::uint8_t>::max() || v[5] > 3 || v[6] > 0xffff ||
      v[7] > 0xffff || (v[0] == 0 && (v[5] || v[6] || v[7])) || (v[1] == 0 && v[4])) {
    return false;
  }
  c->hits = static_cast<std::uint16_t>(v[0]);
  c->free = static_cast<std::uint16_t>(v[1]);
  c->passes = static_cast<std::uint16_t>(v[2]);
  c->ends = static_cast<std::uint16_t>(v[3]);
  c->clear = static_cast<std::uint8_t>(v[4]);
  c->apart = static_cast<std::uint8_t>(v[5] & 1);
  c->moved_in = static_cast<std::uint8_t>(v[5] >> 1);
  c->hit_x = unzigzag(v[6]);
  c->hit_y = unzigzag(v[7]);
  return true;
}

// The bits of a cell's byte encode() keeps: all but what the map has there.
constexpr int kStateShift = 2;
constexpr std::uint64_t kStateBytes = 0xfcfcfcfcfcfcfcfcull;  // of 8 cells at once

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
  weigh(shown(i), c, false);
  switch (kind) {
    case kHit:
      if (c.hits == 0) {
        c.moved_in = (cells_[i] & kPassedBits) >= kMovedInPasses * kPassedOne;
        c.hit_x = place_x_;
        c.hit_y = place_y_;
      } else if (std::hypot(place_x_ - c.hit_x, place_y_ - c.hit_y) * kPlaceUnit >= kMinBaseline) {
        c.apart = 1;
      }
      bump(&c.hits);
      c.clear = 0;
      break;
    case kFree:
      bump(&c.free);
      // A scan that also hit the cell leaves it hit.
      if (!(c.counted & kHit) && c.clear < std::numeric_limits<std::uint8_t>::max()) ++c.clear;
      break;
    case kPass:
      bump(&c.passes);
      break;
    case kEnd:
      bump(&c.ends);
      break;
  }
  show(i, classify(i));
  weigh(shown(i), c, true);
}

void MapChangeLayer::weigh(Cell shown_as, const Counts& c, bool add) {
  if (shown_as != Cell::kAdded && shown_as != Cell::kRemoved) return;
  const bool added = shown_as == Cell::kAdded;
  std::size_t& sum = added ? summary_.added_scans : summary_.removed_scans;
  const std::size_t n = added ? c.hits : c.passes;
  sum = add ? sum + n : sum - n;
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
  std::vector<std::int8_t> out;
  occupancy(&out);
  return out;
}

void MapChangeLayer::occupancy(std::vector<std::int8_t>* out) const {
  static_assert(static_cast<int>(Cell::kUnseen) == 0 && static_cast<int>(Cell::kAsMapped) == 1 &&
                    static_cast<int>(Cell::kAdded) == 2 && static_cast<int>(Cell::kRemoved) == 3,
                "the masks below are valueOf for this order");
  const std::size_t n = cells_.size();  // a local: the bytes written could alias the vector
  out->resize(n);
  std::int8_t* o = out->data();
  const std::uint8_t* c = cells_.data();
  // valueOf(shown(i)) in byte-wide masks, so that the loop vectorizes: -1,
  // 0, 100 and 50 for the two bits 0, 1, 2 and 3 (high: 100 or 50, by the
  // low bit; low alone: 0; neither: -1).
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t s = static_cast<std::uint8_t>(c[i] >> kShownShift);
    const std::uint8_t high = static_cast<std::uint8_t>(-((s >> 1) & 1));
    const std::uint8_t low = static_cast<std::uint8_t>(-(s & 1));
    o[i] = static_cast<std::int8_t>((high & (100 ^ (low & (100 ^ 50)))) | (~high & ~low));
  }
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
  // A free cell is beside an obstacle when its distance's class is below
  // `beside` (distance_field.h). OccupancyGrid::classify's states with masks,
  // without a branch, so that the compiler vectorizes it.
  const auto beside = static_cast<std::uint32_t>(field.classesWithin(kBesideObstacle));
  const int8_t* data = grid.data().data();
  const uint16_t* classes = field.classes();
  cells_.resize(grid.data().size());
  std::uint8_t* cells = cells_.data();
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const int8_t v = data[i];
    const auto occupied = static_cast<std::uint8_t>(-(v >= OccupancyGrid::kOccupiedMin));
    const auto free = static_cast<std::uint8_t>(-(v >= 0 && v <= OccupancyGrid::kFreeMax));
    const std::uint8_t near = std::uint32_t{classes[i]} < beside ? kMapBeside : kMapFree;
    cells[i] = static_cast<std::uint8_t>((occupied & kMapOccupied) | (free & near) |
                                         (~(occupied | free) & kMapUnknown));
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
  const auto place = [](double v) {
    return static_cast<std::int16_t>(std::clamp(std::lround(v / kPlaceUnit), -32767L, 32767L));
  };
  place_x_ = place(robot.x);
  place_y_ = place(robot.y);
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
  const double moved_in_reach = kMovedInRange * frame_.cellsPerMetre();
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
      } else if (map == kMapFree && (cell & kPassedBits) != kPassedBits && t <= moved_in_reach) {
        cell = static_cast<std::uint8_t>(cell + kPassedOne);
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
  // Hits from one place only (the robot turning there, or back there) are
  // what a person standing by gives too: fewer clear scans take them out.
  const int clear_scans = c.apart ? kClearScans : kOnePlaceClearScans;
  if (hits >= kMinScans && hits >= kChangedShare * stopped && c.clear < clear_scans &&
      (!c.moved_in || hits >= kMovedInScans)) {
    return Cell::kAdded;
  }
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

std::string MapChangeLayer::encode() const {
  std::string out;
  putNumber(&out, static_cast<std::uint64_t>(width_));
  putNumber(&out, static_cast<std::uint64_t>(height_));
  putNumber(&out, scans_);
  putReal(&out, last_.x);
  putReal(&out, last_.y);
  putReal(&out, last_.yaw);
  // The cells' states in runs: (length, state) until every cell is covered.
  // An unseen stretch is skipped 8 cells at a time.
  const std::size_t n = cells_.size();
  for (std::size_t i = 0; i < n;) {
    const std::uint8_t state = cells_[i] >> kStateShift;
    std::size_t j = i + 1;
    if (state == 0) {
      for (std::uint64_t w; j + 8 <= n; j += 8) {
        std::memcpy(&w, &cells_[j], sizeof w);
        if (w & kStateBytes) break;
      }
    }
    while (j < n && cells_[j] >> kStateShift == state) ++j;
    putNumber(&out, j - i);
    out.push_back(static_cast<char>(state));
    i = j;
  }
  // The tiles' counts: how many tiles, then each tile's index (from the
  // last's), how many of its cells count, and each one's index in the tile
  // (from the last's) and counts.
  std::string counts;
  std::size_t tiles = 0, last_tile = 0;
  for (std::size_t t = 0; t < tiles_.size(); ++t) {
    if (!tiles_[t]) continue;
    std::string cells;
    std::size_t counted = 0, last_cell = 0;
    for (std::size_t k = 0; k < kTileSize * kTileSize; ++k) {
      const Counts& c = tiles_[t][k];
      if (c.hits == 0 && c.free == 0 && c.passes == 0 && c.ends == 0) continue;
      putNumber(&cells, k - last_cell);
      for (const std::uint16_t v : {c.hits, c.free, c.passes, c.ends}) putNumber(&cells, v);
      putNumber(&cells, c.clear);
      putNumber(&cells, c.apart | c.moved_in << 1);
      putNumber(&cells, zigzag(c.hit_x));
      putNumber(&cells, zigzag(c.hit_y));
      last_cell = k;
      ++counted;
    }
    if (counted == 0) continue;
    putNumber(&counts, t - last_tile);
    putNumber(&counts, counted);
    counts += cells;
    last_tile = t;
    ++tiles;
  }
  putNumber(&out, tiles);
  return out + counts;
}

std::string MapChangeLayer::decode(const std::string& bytes) {
  clear();
  const std::string error = restore(bytes);
  if (!error.empty()) clear();
  return error;
}

// On a cleared layer: encode()'s order, each value checked against the map.
std::string MapChangeLayer::restore(const std::string& bytes) {
  ByteReader in(bytes);
  const std::uint64_t w = in.number(), h = in.number(), scans = in.number();
  const Pose2 last{in.real(), in.real(), in.real()};
  if (!in.ok()) return "truncated";
  if (w != static_cast<std::uint64_t>(width_) || h != static_cast<std::uint64_t>(height_)) {
    return "learned on a map of " + std::to_string(w) + " x " + std::to_string(h) +
           " cells, not this one of " + std::to_string(width_) + " x " + std::to_string(height_);
  }
  if (!last.isFinite()) return "corrupt: the last scan's pose is not finite";
  const std::size_t n = cells_.size();
  for (std::size_t i = 0; i < n;) {
    const std::uint64_t run = in.number();
    const std::uint8_t state = in.byte();
    if (!in.ok()) return "truncated in the cells";
    if (run == 0 || run > n - i) return "corrupt: a run of cells past the map's end";
    const std::uint8_t cell = static_cast<std::uint8_t>(state << kStateShift);
    const auto shown_as = static_cast<Cell>(cell >> kShownShift & 3);
    const bool seen = cell & kSeen;
    if (cell >> kStateShift != state || (cell & ~(kSeen | kWasHit | kShownBits | kPassedBits)) ||
        seen != (shown_as != Cell::kUnseen) || ((cell & (kWasHit | kPassedBits)) && !seen)) {
      return "corrupt: a cell's state is not one the layer gives";
    }
    for (std::size_t k = i; state != 0 && k < i + run; ++k) {
      const std::uint8_t map = cells_[k] & kMapBits;
      if (map == kMapUnknown || ((cell & (kWasHit | kPassedBits)) && map != kMapFree)) {
        return "a cell seen here is unknown on this map, or a beam ended in an obstacle";
      }
      cells_[k] = map | cell;
    }
    i += run;
  }
  const std::uint64_t tiles = in.number();
  if (!in.ok() || tiles > tiles_.size()) return "corrupt: more tiles of counts than the map has";
  std::size_t t = 0;
  for (std::uint64_t k = 0; k < tiles; ++k) {
    const std::uint64_t step = in.number(), counted = in.number();
    if (!in.ok()) return "truncated in the counts";
    if ((k > 0 && step == 0) || step >= tiles_.size() - t || counted == 0 ||
        counted > kTileSize * kTileSize) {
      return "corrupt: a tile of counts out of order or out of the map";
    }
    t += step;
    tiles_[t] = std::make_unique<Counts[]>(kTileSize * kTileSize);
    std::size_t j = 0;
    for (std::uint64_t m = 0; m < counted; ++m) {
      const std::uint64_t cell_step = in.number();
      std::uint64_t v[8];
      for (std::uint64_t& x : v) x = in.number();
      if (!in.ok()) return "truncated in the counts";
      j += cell_step;
      const std::size_t x = (t % tiles_x_) * kTileSize + (j & (kTileSize - 1));
      const std::size_t y = (t / tiles_x_) * kTileSize + (j >> kTileBits);
      if ((m > 0 && cell_step == 0) || j >= kTileSize * kTileSize || x >= std::size_t(width_) ||
          y >= std::size_t(height_) || !(cells_[y * width_ + x] & kSeen)) {
        return "corrupt: counts out of order, out of the map or of an unseen cell";
      }
      Counts& c = tiles_[t][j];
      if (!fillCounts(v, &c)) return "corrupt: a cell's counts are not ones the layer gives";
      // Counted in an earlier scan than the next one added.
      c.scan = static_cast<std::uint16_t>(scans - 1);
    }
  }
  if (!in.atEnd()) return "corrupt: bytes after the counts";
  scans_ = scans;
  last_ = last;
  return summarize();
}

// After restore(): each seen cell must show what its counts say; summary_
// and changed_cells_ follow.
std::string MapChangeLayer::summarize() {
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    if (!(cells_[i] & kSeen)) continue;
    const Cell c = shown(i);
    if (c != classify(i)) return "corrupt: a cell shown otherwise than its counts say";
    ++summary_.seen;
    if (c == Cell::kAdded) ++summary_.added;
    if (c == Cell::kRemoved) ++summary_.removed;
    weigh(c, std::as_const(*this).countsAt(i), true);
    if (c == Cell::kAdded || c == Cell::kRemoved) changed_cells_.push_back(i);
  }
  return "";
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

#include "pf_localization/core/map/map_evidence.h"

#include <algorithm>
#include <cmath>

#include "pf_localization/core/map/distance_field_ray_caster.h"

namespace pf {

EvidenceCounts& EvidenceCounts::operator+=(const EvidenceCounts& o) {
  on_map += o.on_map;
  short_of_map += o.short_of_map;
  through_onto_map += o.through_onto_map;
  through_into_open += o.through_into_open;
  off_map += o.off_map;
  return *this;
}

namespace {

void add(BeamEvidence e, EvidenceCounts* c) {
  switch (e) {
    case BeamEvidence::kOnMap:
      ++c->on_map;
      break;
    case BeamEvidence::kShortOfMap:
      ++c->short_of_map;
      break;
    case BeamEvidence::kThroughOntoMap:
    case BeamEvidence::kThroughOntoAdded:
      ++c->through_onto_map;
      break;
    case BeamEvidence::kThroughIntoOpen:
      ++c->through_into_open;
      break;
    case BeamEvidence::kOffMap:
      ++c->off_map;
      break;
    case BeamEvidence::kNoReading:
      break;
  }
}

}  // namespace

MapEvidence::MapEvidence(const DistanceField& field)
    : field_(&field),
      frame_(field.grid()),
      cells_per_metre_(static_cast<float>(1.0 / field.grid().resolution())) {}

void MapEvidence::setGone(std::size_t cell, bool gone) {
  // Only a mapped obstacle can be gone.
  if (!gone) {
    gone_.erase(cell);
  } else if (OccupancyGrid::classify(field_->grid().data()[cell]) == CellState::kOccupied) {
    gone_.insert(cell);
  }
}

void MapEvidence::setAdded(std::size_t cell, bool added) {
  if (added) {
    added_.insert(cell);
  } else {
    added_.erase(cell);
  }
}

double MapEvidence::cast(double cx, double cy, double dx, double dy, double max_range) const {
  // DistanceFieldRayCaster's trace, each cell's jump worked out from the
  // field's distance as the ray reaches it rather than read from a table.
  const OccupancyGrid& grid = field_->grid();
  const DistanceField& field = *field_;
  const int w = grid.width(), h = grid.height();
  return sphereTrace(cx, cy, dx, dy, max_range, grid.resolution(), w + 2, h + 2, [&](int x, int y) {
    if (x == 0 || y == 0 || x > w || y > h) return kTraceLeaves;  // the border
    const std::size_t i = static_cast<std::size_t>(y - 1) * w + (x - 1);
    // An occupied cell is 0 from the nearest occupied cell: never a jump.
    const float cells = field.distance(i) * cells_per_metre_;
    if (cells > 1.5f) return cells - 1.5f;
    const bool stops =
        OccupancyGrid::classify(grid.data()[i]) == CellState::kOccupied && gone_.count(i) == 0;
    return stops ? kTraceStops : 0.0f;
  });
}

bool MapEvidence::endsOnAdded(double x, double y) const {
  if (added_.empty()) return false;
  const OccupancyGrid& grid = field_->grid();
  const CellIndex c = grid.worldToCell(x, y);
  // Within a cell of one: an end point is a few centimetres off, and a face
  // is learned added where the beams ended most often.
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const CellIndex n{c.x + dx, c.y + dy};
      if (grid.contains(n) && added_.count(static_cast<std::size_t>(grid.linearIndex(n)))) {
        return true;
      }
    }
  }
  return false;
}

BeamEvidence MapEvidence::judge(double sx, double sy, double angle, double range) const {
  return judgeRay(sx, sy, std::cos(angle), std::sin(angle), range);
}

BeamEvidence MapEvidence::judgeRay(double sx, double sy, double ux, double uy, double range) const {
  const OccupancyGrid& grid = field_->grid();
  // An end point just past the map's edge (a wall drawn on it, a little pose
  // error) is judged where the beam leaves the map.
  // Far beams say little of changes and cost the most to cast: on the map.
  if (range > kMaxJudgedRange) return BeamEvidence::kOnMap;
  constexpr int kEdgeSteps = 6;
  double inside = range;
  for (int k = 1; !grid.contains(grid.worldToCell(sx + inside * ux, sy + inside * uy)); ++k) {
    if (k > kEdgeSteps) return BeamEvidence::kOffMap;
    inside = range - kThroughMargin * k / kEdgeSteps;
  }
  const double d = field_->distanceAt(sx + inside * ux, sy + inside * uy);
  // Where the map would stop the beam: its first obstacle along the ray, up to
  // just past the measured end (cast in the grid's frame, in cells).
  double cx, cy, gx, gy;
  frame_.pointInCells(sx, sy, &cx, &cy);
  frame_.directionInGrid(ux, uy, &gx, &gy);
  // An end beside a mapped obstacle is never short of the map: only an
  // obstacle before it matters, and the cast stops there (the last cells
  // before a wall are the ones it crosses one at a time).
  const double reach = d <= kBesideObstacle ? range - kThroughMargin : range + kShortMargin;
  const double expected = cast(cx, cy, gx, gy, reach);
  // An end clear of the map's obstacles, on an object learned added (an
  // object moved a little behind where the map has it), is a change of the
  // map however near the map's obstacle it lies.
  const auto on_added = [&] {
    return d > kBesideObstacle && endsOnAdded(sx + range * ux, sy + range * uy);
  };
  if (expected < range - kThroughMargin) {
    if (d > kOnMapDistance) return BeamEvidence::kThroughIntoOpen;
    return on_added() ? BeamEvidence::kThroughOntoAdded : BeamEvidence::kThroughOntoMap;
  }
  if (expected >= range + kShortMargin && d > kBesideObstacle) return BeamEvidence::kShortOfMap;
  return on_added() ? BeamEvidence::kShortOfMap : BeamEvidence::kOnMap;
}

EvidenceCounts MapEvidence::judge(const LaserScan& scan, const Pose2& robot,
                                  std::vector<BeamEvidence>* out) const {
  EvidenceCounts counts;
  const std::size_t n = scan.ranges.size();
  out->assign(n, BeamEvidence::kNoReading);
  const Pose2 base = compose(robot, scan.robot_offset);
  const bool skewed = !scan.sweep.isStill();
  // A beam's neighbours within the stride see what it sees, near enough.
  const std::size_t stride = std::max<std::size_t>(1, n / kJudgedBeams);
  Pose2 sensor = compose(base, scan.sensor_pose);
  for (std::size_t first = 0; first < n; first += stride) {
    const std::size_t end = std::min(n, first + stride);
    std::size_t i = first;
    while (i < end && !isReading(scan.ranges[i], scan.range_min, scan.range_max)) ++i;
    if (i == end) continue;
    if (skewed) sensor = compose(base, sensorPoseAtBeam(scan.sensor_pose, scan.sweep, i));
    const BeamEvidence e =
        judge(sensor.x, sensor.y,
              sensor.yaw + scan.angle_min + static_cast<double>(i) * scan.angle_increment,
              scan.ranges[i]);
    add(e, &counts);
    for (std::size_t j = i; j < end; ++j) {
      if (isReading(scan.ranges[j], scan.range_min, scan.range_max)) (*out)[j] = e;
    }
  }
  return counts;
}

EvidenceCounts MapEvidence::count(const std::vector<PreparedScan>& scans,
                                  const Pose2& robot) const {
  EvidenceCounts counts;
  for (const PreparedScan& s : scans) {
    const Pose2 sensor = compose(robot, {s.sensor_x, s.sensor_y, 0.0});
    for (std::size_t b = 0; b < s.size(); ++b) {
      const Pose2 end = compose(robot, {s.x[b], s.y[b], 0.0});
      const double dx = end.x - sensor.x, dy = end.y - sensor.y;
      add(judge(sensor.x, sensor.y, std::atan2(dy, dx), std::hypot(dx, dy)), &counts);
    }
  }
  return counts;
}

}  // namespace pf

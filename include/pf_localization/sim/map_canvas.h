// A canvas the simulator's maps are drawn on, cell by cell, in map-frame
// metres: boxes, discs, thick segments and triangles of free, occupied or
// unknown cells (building_map.h, warehouse_map.h, map_changes.h).
#pragma once

#include <cstdint>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf::sim {

/// An axis-aligned rectangle in metres.
struct Box {
  double x0, y0, x1, y1;
};

/// Draws a map cell by cell. A cell belongs to a shape when its centre does.
class MapCanvas {
 public:
  static constexpr int8_t kFree = 0;
  static constexpr int8_t kOccupied = 100;
  static constexpr int8_t kUnknown = -1;

  /// A canvas covering `extent`, all unknown.
  MapCanvas(const Box& extent, double resolution);

  void fill(const Box& box, int8_t value);
  void disc(double cx, double cy, double radius, int8_t value);
  /// A straight wall of the given thickness between two points.
  void segment(double x0, double y0, double x1, double y1, double thickness, int8_t value);

  void triangle(double ax, double ay, double bx, double by, double cx, double cy, int8_t value);

  OccupancyGrid grid() const;

 private:
  template <typename Inside>
  void paint(const Box& bounds, int8_t value, Inside inside);

  Box extent_;
  double resolution_;
  int width_, height_;
  std::vector<int8_t> data_;
};

}  // namespace pf::sim

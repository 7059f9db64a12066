#include "pf_localization/sim/map_canvas.h"

#include <algorithm>
#include <cmath>

namespace pf::sim {

MapCanvas::MapCanvas(const Box& extent, double resolution)
    : extent_(extent),
      resolution_(resolution),
      width_(static_cast<int>(std::lround((extent.x1 - extent.x0) / resolution))),
      height_(static_cast<int>(std::lround((extent.y1 - extent.y0) / resolution))),
      data_(static_cast<std::size_t>(width_) * height_, kUnknown) {}

template <typename Inside>
void MapCanvas::paint(const Box& bounds, int8_t value, Inside inside) {
  const auto first = [&](double lo, double origin) {
    return std::max(0, static_cast<int>(std::floor((lo - origin) / resolution_)));
  };
  const int i0 = first(bounds.x0, extent_.x0), j0 = first(bounds.y0, extent_.y0);
  for (int j = j0; j < height_; ++j) {
    const double y = extent_.y0 + (j + 0.5) * resolution_;
    if (y > bounds.y1) break;
    for (int i = i0; i < width_; ++i) {
      const double x = extent_.x0 + (i + 0.5) * resolution_;
      if (x > bounds.x1) break;
      if (x >= bounds.x0 && y >= bounds.y0 && inside(x, y)) data_[j * width_ + i] = value;
    }
  }
}

void MapCanvas::fill(const Box& box, int8_t value) {
  paint(box, value, [](double, double) { return true; });
}

void MapCanvas::disc(double cx, double cy, double radius, int8_t value) {
  paint({cx - radius, cy - radius, cx + radius, cy + radius}, value,
        [&](double x, double y) { return std::hypot(x - cx, y - cy) <= radius; });
}

void MapCanvas::segment(double x0, double y0, double x1, double y1, double thickness,
                        int8_t value) {
  const double h = 0.5 * thickness;
  const double dx = x1 - x0, dy = y1 - y0;
  const double length2 = dx * dx + dy * dy;
  const Box bounds{std::min(x0, x1) - h, std::min(y0, y1) - h, std::max(x0, x1) + h,
                   std::max(y0, y1) + h};
  paint(bounds, value, [&](double x, double y) {
    const double t = std::clamp(((x - x0) * dx + (y - y0) * dy) / length2, 0.0, 1.0);
    return std::hypot(x - (x0 + t * dx), y - (y0 + t * dy)) <= h;
  });
}

void MapCanvas::triangle(double ax, double ay, double bx, double by, double cx, double cy,
                         int8_t value) {
  // Inside when the point is on the same side of all three edges.
  const auto side = [](double px, double py, double qx, double qy, double x, double y) {
    return (qx - px) * (y - py) - (qy - py) * (x - px);
  };
  const Box bounds{std::min({ax, bx, cx}), std::min({ay, by, cy}), std::max({ax, bx, cx}),
                   std::max({ay, by, cy})};
  paint(bounds, value, [&](double x, double y) {
    const double s1 = side(ax, ay, bx, by, x, y), s2 = side(bx, by, cx, cy, x, y),
                 s3 = side(cx, cy, ax, ay, x, y);
    return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
  });
}

OccupancyGrid MapCanvas::grid() const {
  return OccupancyGrid(width_, height_, resolution_, {extent_.x0, extent_.y0, 0.0}, data_);
}

}  // namespace pf::sim

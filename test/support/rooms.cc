#include "support/rooms.h"

#include <cmath>
#include <cstdint>

namespace pf::test {

OccupancyGrid room(double width, double height, double resolution, const std::vector<Box>& boxes,
                   const Pose2& origin) {
  const int w = static_cast<int>(std::lround(width / resolution));
  const int h = static_cast<int>(std::lround(height / resolution));
  std::vector<int8_t> data(static_cast<std::size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double cx = (x + 0.5) * resolution, cy = (y + 0.5) * resolution;
      bool occupied = x == 0 || y == 0 || x == w - 1 || y == h - 1;
      for (const Box& b : boxes) {
        occupied = occupied || (cx > b.x0 && cx < b.x1 && cy > b.y0 && cy < b.y1);
      }
      data[static_cast<std::size_t>(y) * w + x] = occupied ? 100 : 0;
    }
  }
  return OccupancyGrid(w, h, resolution, origin, data);
}

OccupancyGrid tenMetreRoom(bool walls) {
  if (walls) return room(10.0, 10.0, 0.05);
  return OccupancyGrid(200, 200, 0.05, {}, std::vector<int8_t>(200 * 200, 0));
}

OccupancyGrid asymmetricRoom() {
  return room(4.0, 3.0, 0.05, {{2.5, 0.5, 3.0, 1.2}, {0.6, 2.0, 1.0, 2.4}});
}

OccupancyGrid wallGrid(int column, const Pose2& origin) {
  std::vector<int8_t> data(50, 0);
  for (int y = 0; y < 5; ++y) data[y * 10 + column] = 100;
  return OccupancyGrid(10, 5, 0.1, origin, data);
}

OccupancyGrid changedRoomWorld() { return room(6.0, 4.0, 0.05, {kChangedRoomAdded}); }
OccupancyGrid changedRoomMap() { return room(6.0, 4.0, 0.05, {kChangedRoomRemoved}); }

std::vector<Pose2> changedRoomTour() {
  return {{3.0, 2.0, 0.0}, {2.6, 1.2, 0.5}, {2.0, 1.0, 1.6}, {3.2, 2.8, -2.0}, {2.5, 2.2, 3.0}};
}

}  // namespace pf::test

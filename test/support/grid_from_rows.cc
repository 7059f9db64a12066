#include "support/grid_from_rows.h"

#include <cstdint>
#include <stdexcept>

namespace pf::test {

namespace {

int8_t cellValue(char c) {
  switch (c) {
    case '#':
      return 100;
    case '.':
      return 0;
    case '?':
      return -1;
    default:
      throw std::invalid_argument(std::string("gridFromRows: unknown cell '") + c +
                                  "' (expected '#', '.' or '?')");
  }
}

}  // namespace

OccupancyGrid gridFromRows(const std::vector<std::string>& rows, double resolution,
                           const Pose2& origin) {
  if (rows.empty() || rows[0].empty()) throw std::invalid_argument("gridFromRows: no cells");
  const int h = static_cast<int>(rows.size()), w = static_cast<int>(rows[0].size());
  std::vector<int8_t> data(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    const std::string& row = rows[h - 1 - y];
    if (static_cast<int>(row.size()) != w) {
      throw std::invalid_argument("gridFromRows: rows of different lengths");
    }
    for (int x = 0; x < w; ++x) data[static_cast<std::size_t>(y) * w + x] = cellValue(row[x]);
  }
  return OccupancyGrid(w, h, resolution, origin, data);
}

}  // namespace pf::test

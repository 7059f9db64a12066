#include "support/closed_region.h"

#include <queue>
#include <vector>

namespace pf::test {

int closedRegionSize(const OccupancyGrid& g, double x, double y) {
  std::vector<bool> seen(g.data().size(), false);
  std::queue<CellIndex> todo;
  const CellIndex start = g.worldToCell(x, y);
  if (g.state(start) != CellState::kFree) return 0;
  todo.push(start);
  seen[g.linearIndex(start)] = true;
  int count = 0;
  while (!todo.empty()) {
    const CellIndex c = todo.front();
    todo.pop();
    ++count;
    for (const CellIndex n : {CellIndex{c.x + 1, c.y}, CellIndex{c.x - 1, c.y},
                              CellIndex{c.x, c.y + 1}, CellIndex{c.x, c.y - 1}}) {
      // Off the map, state() is unknown too.
      const CellState s = g.state(n);
      if (s == CellState::kUnknown) return -1;
      if (s == CellState::kFree && !seen[g.linearIndex(n)]) {
        seen[g.linearIndex(n)] = true;
        todo.push(n);
      }
    }
  }
  return count;
}

}  // namespace pf::test

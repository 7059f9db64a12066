#include "pf_localization/core/map/distance_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "pf_localization/core/map/distance_transform.h"
#include "pf_localization/core/util/worker_pool.h"

namespace pf {

// The distinct values a cell can take, and each squared distance's class.
// Off obstacles a cell at k squared cells from the nearest obstacle is
// outside(k) metres from it; an occupied cell k squared cells from the
// nearest cell that is not occupied is inside(k) (negated, <= 0). Both reach
// the cap at some k and stay there: only the k below it are listed.
struct DistanceField::ValueClasses {
  ValueClasses(float res, float cap) : res(res), cap(cap) {
    outside_cap = firstAt(cap, [this](int64_t k) { return outside(k); });
    inside_cap = firstAt(-cap, [this](int64_t k) { return inside(k); });
    outside_reach = reach(outside_cap);
    inside_reach = reach(inside_cap);
    // The squared distances that occur: sums of two squares.
    const int64_t top = std::max(outside_cap, inside_cap);
    std::vector<bool> occurs(static_cast<std::size_t>(top), false);
    for (int64_t a = 0; a * a < top; ++a) {
      for (int64_t b = a; a * a + b * b < top; ++b) occurs[a * a + b * b] = true;
    }
    for (int64_t k = 0; k < top; ++k) {
      if (!occurs[k]) continue;
      if (k < outside_cap) values.push_back(outside(k));
      if (k < inside_cap) values.push_back(inside(k));
    }
    values.push_back(cap);
    values.push_back(-cap);
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    for (float& v : values) v = v == 0.0f ? 0.0f : v;  // -0 and +0 are one value: +0
    // Past kMaxClasses, runs of neighbouring values share a class, the
    // first one's value.
    const std::size_t n = values.size();
    const auto classOfRank = [n](std::size_t r) {
      return n <= kMaxClasses ? r : r * kMaxClasses / n;
    };
    const auto classOf = [&](float v) {
      const auto r = std::lower_bound(values.begin(), values.end(), v) - values.begin();
      return static_cast<uint16_t>(classOfRank(static_cast<std::size_t>(r)));
    };
    of_outside.resize(static_cast<std::size_t>(outside_cap));
    of_inside.resize(static_cast<std::size_t>(inside_cap));
    for (int64_t k = 0; k < top; ++k) {
      if (!occurs[k]) continue;
      if (k < outside_cap) of_outside[k] = classOf(outside(k));
      if (k < inside_cap) of_inside[k] = classOf(inside(k));
    }
    outside_cap_class = classOf(cap);
    inside_cap_class = classOf(-cap);
    if (n > kMaxClasses) {
      std::vector<float> merged(kMaxClasses);
      for (std::size_t r = n; r-- > 0;) merged[classOfRank(r)] = values[r];
      values = std::move(merged);
    }
  }

  float outside(int64_t k) const { return std::min(std::sqrt(static_cast<float>(k)) * res, cap); }
  float inside(int64_t k) const {
    return -std::min(std::max(std::sqrt(static_cast<float>(k)) - 1.0f - kFreeDepth, 0.0f) * res,
                     cap);
  }
  // The first squared distance whose value is `end` (then so are all after it).
  template <typename Value>
  static int64_t firstAt(float end, Value value) {
    int64_t k = 0;
    while (value(k) != end) ++k;
    return k;
  }
  // The first column distance whose square reaches `k_cap`.
  static uint16_t reach(int64_t k_cap) {
    int64_t g = 0;
    while (g * g < k_cap) ++g;
    return static_cast<uint16_t>(g);
  }
  // The class of squared distance d (-1: no source below the cap).
  static uint16_t classOf(int64_t d, int64_t k_cap, const std::vector<uint16_t>& of,
                          uint16_t cap_class) {
    return d < 0 || d >= k_cap ? cap_class : of[static_cast<std::size_t>(d)];
  }

  float res, cap;
  int64_t outside_cap, inside_cap;       // the first squared distance at the cap
  uint16_t outside_reach, inside_reach;  // the first column distance at it
  std::vector<uint16_t> of_outside, of_inside;
  uint16_t outside_cap_class, inside_cap_class;
  std::vector<float> values;  // per class
};

DistanceField::DistanceField(OccupancyGrid grid, double max_distance, int threads)
    : grid_(std::move(grid)), max_distance_(max_distance) {
  if (!(max_distance > 0.0) || !std::isfinite(max_distance)) {
    throw std::invalid_argument("likelihood field: max_distance must be positive and finite, got " +
                                std::to_string(max_distance));
  }
  if (max_distance / grid_.resolution() > kMaxCapCells) {
    throw std::invalid_argument("likelihood field: max_distance " + std::to_string(max_distance) +
                                " m is more than " +
                                std::to_string(static_cast<int>(kMaxCapCells)) + " cells of " +
                                std::to_string(grid_.resolution()) + " m");
  }
  if (grid_.width() > kMaxRowPassCells) {
    throw std::invalid_argument("likelihood field: the map is " + std::to_string(grid_.width()) +
                                " cells wide, more than the " + std::to_string(kMaxRowPassCells) +
                                " its distance transform takes");
  }
  const ValueClasses values(static_cast<float>(grid_.resolution()),
                            static_cast<float>(max_distance));
  classes_.assign(grid_.data().size() + 1, values.outside_cap_class);
  transformOutside(values, threads);
  transformInside(values, threads);
  distances_.resize(values.values.size());
  surfaces_.resize(values.values.size());
  for (std::size_t c = 0; c < values.values.size(); ++c) {
    const float v = values.values[c];
    distances_[c] = v > 0.0f ? v : 0.0f;
    surfaces_[c] = std::fabs(v);
  }
  if (size() <= kMaxFloatCells) {
    surface_cells_.resize(size());
    for (std::size_t i = 0; i < size(); ++i) surface_cells_[i] = surfaces_[classes_[i]];
  }
}

namespace {

// Calls part(begin, end) for `parts` even slices of [0, n), on up to
// `threads` threads.
template <typename Part>
void inSlices(int threads, std::size_t n, Part part) {
  const std::size_t parts = static_cast<std::size_t>(std::max(threads, 1));
  auto task = [&](std::size_t k) { part(n * k / parts, n * (k + 1) / parts); };
  WorkerPool::instance().run(threads, parts, task);
}

// One row of transformInside's column pass from the row before it (kMin:
// the pass back up, which keeps the smaller): an occupied cell is one more
// than its neighbour's column distance (0 for a cell that is not occupied),
// at most cap. Without a branch on the cells' states, and on pointers that
// do not alias, so that the compiler vectorizes it.
template <bool kMin>
void insideColumnStep(const int8_t* __restrict from_map, const uint16_t* __restrict from,
                      const int8_t* __restrict to_map, uint16_t* __restrict to, std::size_t count,
                      uint16_t cap) {
  const auto mask = [](int8_t value) {
    return static_cast<uint16_t>(-static_cast<int>(value >= OccupancyGrid::kOccupiedMin));
  };
  for (std::size_t k = 0; k < count; ++k) {
    // An occupied cell's entry is at most cap already.
    const uint16_t column = from[k] & mask(from_map[k]);
    const uint16_t below = std::min(static_cast<uint16_t>(column + 1), cap);
    const uint16_t now = to[k], keep = mask(to_map[k]);
    const uint16_t step = kMin ? std::min(now, below) : below;
    to[k] = static_cast<uint16_t>((step & keep) | (now & ~keep));
  }
}

}  // namespace

void DistanceField::transformOutside(const ValueClasses& values, int threads) {
  const int w = grid_.width(), h = grid_.height();
  uint16_t* cells = classes_.data();
  const int8_t* map = grid_.data().data();
  // The column distances, then each row's classes in their place.
  inSlices(threads, static_cast<std::size_t>(w), [&](std::size_t begin, std::size_t end) {
    cappedColumnDistances(
        map, [](int8_t v) { return DistanceField::occupied(v); }, w, h, values.outside_reach,
        static_cast<int>(begin), static_cast<int>(end), cells);
  });
  inSlices(threads, static_cast<std::size_t>(h), [&](std::size_t begin, std::size_t end) {
    RowPassScratch scratch;
    std::vector<uint16_t> g(static_cast<std::size_t>(w));
    std::vector<int32_t> d(static_cast<std::size_t>(w));
    for (std::size_t y = begin; y < end; ++y) {
      uint16_t* row = cells + y * w;
      std::copy(row, row + w, g.begin());
      cappedRowPass(g.data(), w, values.outside_reach, &scratch, d.data());
      for (int x = 0; x < w; ++x) {
        row[x] = ValueClasses::classOf(d[x], values.outside_cap, values.of_outside,
                                       values.outside_cap_class);
      }
    }
  });
}

void DistanceField::transformInside(const ValueClasses& values, int threads) {
  const int w = grid_.width(), h = grid_.height();
  const std::size_t n = grid_.data().size();
  const int8_t* map = grid_.data().data();
  const auto occupied = [map](std::size_t i) { return DistanceField::occupied(map[i]); };
  uint16_t* cells = classes_.data();
  // The column pass (cappedColumnDistances' to the cells that are not
  // occupied) kept in the occupied cells' own entries, whose classes come
  // after it: a cell that is not occupied is 0 from itself.
  const uint16_t cap = values.inside_reach;
  const auto column = [&](std::size_t i) { return occupied(i) ? cells[i] : uint16_t{0}; };
  inSlices(threads, static_cast<std::size_t>(w), [&](std::size_t begin, std::size_t end) {
    const std::size_t count = end - begin;
    for (std::size_t x = begin; x < end; ++x) {
      if (occupied(x)) cells[x] = cap;
    }
    for (std::size_t row = w; row < n; row += w) {
      insideColumnStep<false>(map + row - w + begin, cells + row - w + begin, map + row + begin,
                              cells + row + begin, count, cap);
    }
    for (std::size_t row = n - w; row >= static_cast<std::size_t>(w);) {
      row -= w;
      insideColumnStep<true>(map + row + w + begin, cells + row + w + begin, map + row + begin,
                             cells + row + begin, count, cap);
    }
  });
  // Along a row, the cell that is not occupied just before (after) a run of
  // occupied cells is nearer than any before (after) it: each run's row pass
  // needs only the run and those two cells.
  inSlices(threads, static_cast<std::size_t>(h), [&](std::size_t begin, std::size_t end) {
    RowPassScratch scratch;
    std::vector<uint16_t> g(static_cast<std::size_t>(w));
    std::vector<int32_t> d(static_cast<std::size_t>(w));
    for (std::size_t y = begin; y < end; ++y) {
      const std::size_t row = y * w;
      for (int a = 0; a < w;) {
        if (!occupied(row + a)) {
          ++a;
          continue;
        }
        int b = a;
        while (b + 1 < w && occupied(row + b + 1)) ++b;
        const int first = std::max(a - 1, 0), last = std::min(b + 1, w - 1);
        for (int x = first; x <= last; ++x) g[x - first] = column(row + x);
        cappedRowPass(g.data(), last - first + 1, cap, &scratch, d.data());
        for (int x = a; x <= b; ++x) {
          classes_[row + x] = ValueClasses::classOf(d[x - first], values.inside_cap,
                                                    values.of_inside, values.inside_cap_class);
        }
        a = b + 1;
      }
    }
  });
}

}  // namespace pf

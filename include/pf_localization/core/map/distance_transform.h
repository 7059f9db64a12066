// Exact Euclidean distance transform of a binary grid.
//
// The squared distance is separable: the distance to the nearest source in
// each column, then along each row the lower envelope of the parabolas
// rooted at the columns' squared distances, gives the exact result in
// O(width * height). The column pass is the first phase of Meijster,
// Roerdink & Hesselink, "A General Algorithm for Computing Distance
// Transforms in Linear Time" (2000): two sweeps, done a row at a time so that
// memory is read in order. The row pass is Felzenszwalb & Huttenlocher,
// "Distance Transforms of Sampled Functions", Theory of Computing 8 (2012).
// Apart from a row of scratch, the result is the only memory it takes: each
// fresh page costs a page fault, and a map at 2 cm has millions of cells.
//
// A transform that only needs distances below a cap (the likelihood field's)
// runs the same two passes on 16-bit column distances, and leaves out of the
// row pass every source whose column distance alone reaches the cap: what it
// gives is the exact squared distance wherever that is below the cap.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pf {

/// Squared distance, in cells, from every cell to the nearest cell whose
/// `is_source` flag is set (row-major, width * height). Cells with no source
/// at all in the grid get +infinity.
std::vector<float> squaredDistanceTransform(const std::vector<bool>& is_source, int width,
                                            int height);

/// One row of cappedColumnDistances' pass down (from the row above) or back
/// up (kUp: from the row below, keeping the smaller). On pointers that do
/// not alias and without a branch, so that the compiler vectorizes it.
template <bool kUp, typename Value, typename IsSource>
void cappedColumnStep(const Value* __restrict values, const IsSource& is_source,
                      const uint16_t* __restrict from, uint16_t* __restrict out, std::size_t count,
                      uint16_t cap) {
  for (std::size_t k = 0; k < count; ++k) {
    // Entries are at most cap, so min(g + 1, cap) is g + 1 below it.
    const auto next = std::min(static_cast<uint16_t>(from[k] + 1), cap);
    if constexpr (kUp) {
      out[k] = std::min(out[k], next);
    } else {
      out[k] = is_source(values[k]) ? uint16_t{0} : next;
    }
  }
}

/// The column pass for distances below `cap` cells: out[y * width + x] is
/// the distance in cells from (x, y) to the nearest source in column x, or
/// `cap` when that is `cap` or more (or the column has none); cell i
/// (row-major) is a source when is_source(values[i]). Columns [x_begin,
/// x_end) only, so that threads can share a grid.
template <typename Value, typename IsSource>
void cappedColumnDistances(const Value* values, const IsSource& is_source, int width, int height,
                           uint16_t cap, int x_begin, int x_end, uint16_t* out) {
  const std::size_t w = static_cast<std::size_t>(width);
  const std::size_t n = w * static_cast<std::size_t>(height);
  if (n == 0 || x_begin >= x_end) return;
  const std::size_t first = static_cast<std::size_t>(x_begin);
  const std::size_t count = static_cast<std::size_t>(x_end) - first;
  for (std::size_t x = first; x < first + count; ++x) out[x] = is_source(values[x]) ? 0 : cap;
  for (std::size_t row = w; row < n; row += w) {
    cappedColumnStep<false>(values + row + first, is_source, out + row - w + first,
                            out + row + first, count, cap);
  }
  for (std::size_t row = n - w; row >= w;) {
    row -= w;
    cappedColumnStep<true>(values + row + first, is_source, out + row + w + first,
                           out + row + first, count, cap);
  }
}

/// The scratch of cappedRowPass, kept between rows: the lower envelope's
/// parabolas (their columns) and the boundaries between them, each the
/// fraction z_num / z_den (z_den > 0).
struct RowPassScratch {
  std::vector<int> v;
  std::vector<int64_t> z_num;
  std::vector<int64_t> z_den;
};

/// The longest row cappedRowPass takes: its integer arithmetic stays below
/// 2^62 up to it.
constexpr int kMaxRowPassCells = 1 << 20;

/// The row pass over one row of column distances g[0, n) from
/// cappedColumnDistances with the same `cap`: d[x] = min over x' of
/// (x - x')^2 + g[x']^2 over the sources with g[x'] < cap, where that is
/// below cap^2; -1 where there is no such source, and maybe where it is
/// cap^2 or more (a source cap or more columns away). n at most
/// kMaxRowPassCells.
void cappedRowPass(const uint16_t* g, int n, uint16_t cap, RowPassScratch* scratch, int32_t* d);

}  // namespace pf

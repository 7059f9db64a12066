#include "pf_localization/core/map/distance_transform.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace pf {
namespace {

// Stands in for "no source" inside the row pass: large enough never to win
// against a real source, and finite so that no inf - inf turns into NaN.
constexpr double kFar = 1e20;

// One pass of Felzenszwalb-Huttenlocher over n samples of f: d[q] = min_p
// (q - p)^2 + f[p], the lower envelope of parabolas rooted at every p. v
// holds the envelope's parabolas, z the boundaries between them.
void transform1d(const double* f, int n, double* d, std::vector<int>& v, std::vector<double>& z) {
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  for (int q = 1; q < n; ++q) {
    // z[0] is -inf and s is finite (kFar is), so k never drops below 0.
    const double fq = f[q] + static_cast<double>(q) * q;
    double s;
    while (true) {
      const int p = v[k];
      s = (fq - (f[p] + static_cast<double>(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    const double dq = q - v[k];
    d[q] = dq * dq + f[v[k]];
  }
}

}  // namespace

std::vector<float> squaredDistanceTransform(const std::vector<bool>& is_source, int width,
                                            int height) {
  const std::size_t n = static_cast<std::size_t>(width) * height;
  if (is_source.size() != n) {
    throw std::invalid_argument("squaredDistanceTransform: " + std::to_string(is_source.size()) +
                                " flags for a " + std::to_string(width) + " x " +
                                std::to_string(height) + " grid");
  }
  if (n == 0) return {};
  const std::size_t w = static_cast<std::size_t>(width);
  constexpr float kNone = std::numeric_limits<float>::infinity();

  // Down the columns, a row at a time so that memory is read in order: each
  // cell's distance in cells to the nearest source in its own column (inf
  // when the column has none; inf + 1 stays inf). Below, then above.
  std::vector<float> out(n);
  for (std::size_t x = 0; x < w; ++x) out[x] = is_source[x] ? 0.0f : kNone;
  for (std::size_t i = w; i < n; ++i) out[i] = is_source[i] ? 0.0f : out[i - w] + 1.0f;
  for (std::size_t i = n - w; i-- > 0;) out[i] = std::min(out[i], out[i + w] + 1.0f);

  // Along each row, the lower envelope of the columns' squared distances.
  std::vector<double> f(w), d(w);
  std::vector<int> v(w);
  std::vector<double> z(w + 1);
  for (std::size_t row = 0; row < n; row += w) {
    float* cells = &out[row];
    for (std::size_t x = 0; x < w; ++x) {
      const double g = cells[x];
      f[x] = cells[x] == kNone ? kFar : g * g;
    }
    transform1d(f.data(), width, d.data(), v, z);
    for (std::size_t x = 0; x < w; ++x) {
      cells[x] = d[x] >= kFar / 2 ? kNone : static_cast<float>(d[x]);
    }
  }
  return out;
}

void cappedRowPass(const uint16_t* g, int n, uint16_t cap, RowPassScratch* scratch, int32_t* d) {
  std::vector<int>& v = scratch->v;
  std::vector<int64_t>& z_num = scratch->z_num;
  std::vector<int64_t>& z_den = scratch->z_den;
  v.resize(static_cast<std::size_t>(n));
  z_num.resize(static_cast<std::size_t>(n));
  z_den.resize(static_cast<std::size_t>(n));
  // f(p) + p^2, the numerators' parts: below 2^17 + n^2.
  const auto h = [g](int p) { return int64_t{g[p]} * g[p] + int64_t{p} * p; };
  // Felzenszwalb-Huttenlocher's envelope (transform1d above), over the
  // sources that can reach below the cap only, in integers: the boundary
  // between the parabolas at p < q is (h(q) - h(p)) / (2 (q - p)), and
  // boundaries are compared by cross-multiplying (the products stay below
  // 2^62 for rows of up to 2^20 cells), not divided. The first boundary is
  // -inf: once a source is in, k never drops below 0.
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (g[q] >= cap) continue;
    const int64_t hq = h(q);
    int64_t num = 0, den = 1;
    while (k >= 0) {
      const int p = v[k];
      num = hq - h(p);
      den = 2 * int64_t{q - p};
      if (k == 0 || num * z_den[k] > z_num[k] * den) break;
      --k;
    }
    ++k;
    v[k] = q;
    z_num[k] = num;
    z_den[k] = den;
  }
  if (k < 0) {
    std::fill(d, d + n, -1);
    return;
  }
  // Parabola j holds the cells up to floor(z[j + 1]); a double's quotient
  // floors exactly, as a fraction of denominator below 2^21 is never within
  // 2^-21 of an integer it is not. Within a parabola's cells, those fewer
  // than cap columns from its source get its distance, the others -1.
  int q = 0;
  for (int j = 0; j <= k && q < n; ++j) {
    int last = n - 1;
    if (j < k) {
      const double z = static_cast<double>(z_num[j + 1]) / static_cast<double>(z_den[j + 1]);
      last = static_cast<int>(std::clamp<double>(std::floor(z), -1.0, n - 1.0));
    }
    if (last < q) continue;
    const int p = v[j];
    const int32_t gp2 = int32_t{g[p]} * g[p];
    const int lo = std::clamp(p - cap + 1, q, last + 1), hi = std::min(last, p + cap - 1);
    for (; q < lo; ++q) d[q] = -1;
    for (; q <= hi; ++q) d[q] = (q - p) * (q - p) + gp2;
    for (; q <= last; ++q) d[q] = -1;
  }
}

}  // namespace pf

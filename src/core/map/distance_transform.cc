#include "pf_localization/core/map/distance_transform.h"

#include <algorithm>
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
  std::vector<double>& z = scratch->z;
  v.resize(static_cast<std::size_t>(n));
  z.resize(static_cast<std::size_t>(n) + 1);
  const auto f = [g](int p) { return static_cast<double>(g[p]) * g[p]; };
  // Felzenszwalb-Huttenlocher's envelope (transform1d above), over the
  // sources that can reach below the cap only; z[0] is -inf, so once a
  // source is in, k never drops below 0.
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (g[q] >= cap) continue;
    const double fq = f(q) + static_cast<double>(q) * q;
    double s = -std::numeric_limits<double>::infinity();
    while (k >= 0) {
      const int p = v[k];
      s = (fq - (f(p) + static_cast<double>(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = s;
  }
  if (k < 0) {
    std::fill(d, d + n, -1);
    return;
  }
  z[k + 1] = std::numeric_limits<double>::infinity();
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const int dq = std::abs(q - v[j]);
    d[q] = dq < cap ? dq * dq + int32_t{g[v[j]]} * g[v[j]] : -1;
  }
}

}  // namespace pf

#include "pf_localization/core/distance_transform.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace pf {
namespace {

// Stands in for "no source" inside the passes: large enough never to win
// against a real source, and finite so that no inf - inf turns into NaN.
constexpr double kFar = 1e20;

// One pass of Felzenszwalb-Huttenlocher over n samples of f (with a stride):
// d[q] = min_p (q - p)^2 + f[p], the lower envelope of parabolas rooted at
// every p. v holds the envelope's parabolas, z the boundaries between them.
void transform1d(const double* f, int n, int stride, double* d, std::vector<int>& v,
                 std::vector<double>& z) {
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  for (int q = 1; q < n; ++q) {
    // z[0] is -inf and s is finite (kFar is), so k never drops below 0.
    const double fq = f[q * stride] + static_cast<double>(q) * q;
    double s;
    while (true) {
      const int p = v[k];
      s = (fq - (f[p * stride] + static_cast<double>(p) * p)) / (2.0 * (q - p));
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
    d[q * stride] = dq * dq + f[v[k] * stride];
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
  std::vector<double> f(n), g(n);
  for (std::size_t i = 0; i < n; ++i) f[i] = is_source[i] ? 0.0 : kFar;

  const int longest = std::max(width, height);
  std::vector<int> v(longest);
  std::vector<double> z(longest + 1);
  for (int x = 0; x < width; ++x) transform1d(&f[x], height, width, &g[x], v, z);
  for (int y = 0; y < height; ++y) {
    transform1d(&g[static_cast<std::size_t>(y) * width], width, 1,
                &f[static_cast<std::size_t>(y) * width], v, z);
  }

  std::vector<float> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = f[i] >= kFar / 2 ? std::numeric_limits<float>::infinity() : static_cast<float>(f[i]);
  }
  return out;
}

}  // namespace pf

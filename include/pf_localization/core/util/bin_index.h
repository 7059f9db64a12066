// The histogram bin of a coordinate, safe for any double.
//
// Particles can end up anywhere after a faulty odometry step or with tiny bin
// sizes, and converting a double outside the integer range (or NaN) to an
// integer is undefined behaviour. Bins are clamped to +-2^52, far beyond any
// real map, and NaN goes to bin 0.
#pragma once

#include <cmath>
#include <cstdint>

namespace pf {

inline int64_t binIndex(double value, double bin_size) {
  constexpr double kLimit = 4503599627370496.0;  // 2^52
  const double bin = std::floor(value / bin_size);
  if (!(bin > -kLimit)) return std::isnan(bin) ? 0 : -static_cast<int64_t>(kLimit);
  if (!(bin < kLimit)) return static_cast<int64_t>(kLimit);
  return static_cast<int64_t>(bin);
}

}  // namespace pf

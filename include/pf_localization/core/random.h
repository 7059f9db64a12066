// The filter's single source of randomness. Seeded explicitly so that the same
// seed and the same input always give the same particles.
#pragma once

#include <cstdint>
#include <random>

namespace pf {

class Random {
 public:
  explicit Random(uint64_t seed) : engine_(seed) {}

  /// Uniform in [0, 1).
  double uniform() { return std::uniform_real_distribution<double>(0.0, 1.0)(engine_); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n).
  uint64_t index(uint64_t n) { return std::uniform_int_distribution<uint64_t>(0, n - 1)(engine_); }
  /// Zero-mean normal with standard deviation sigma (sigma <= 0 gives 0).
  double gaussian(double sigma) { return sigma > 0.0 ? sigma * normal_(engine_) : 0.0; }

 private:
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace pf

// The filter's single source of randomness. Seeded explicitly so that the same
// seed and the same input always give the same particles, on any standard
// library: the generator and both distributions are implemented here.
//
// Engine: xoshiro256++ (Blackman & Vigna, "Scrambled Linear Pseudorandom
// Number Generators", ACM TOMS 47(4), 2021), seeded through splitmix64.
// Normal variates: the ziggurat method (Marsaglia & Tsang, "The Ziggurat
// Method for Generating Random Variables", J. Stat. Software 5(8), 2000) with
// 128 layers: one 64-bit draw and a compare for 98.8% of the samples. The
// motion model draws three normals per particle per update, so this is on
// the filter's hot path.
#pragma once

#include <array>
#include <cstdint>

namespace pf {

// The ziggurat's 128 layers (random.cc): k are the acceptance bounds, w the
// scale from integer to x, f the density at each layer's edge.
struct ZigguratTables {
  uint32_t k[128];
  double w[128];
  double f[128];
};

class Random {
 public:
  explicit Random(uint64_t seed);

  /// 64 uniformly random bits.
  uint64_t bits() {
    const uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(bits() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n), n >= 1 (Lemire's multiply-shift; its bias
  /// below 2^-40 for any n a map can have is irrelevant here).
  uint64_t index(uint64_t n) {
    return static_cast<uint64_t>((static_cast<unsigned __int128>(bits()) * n) >> 64);
  }
  /// Standard normal variate. The common case is inline, so that a loop
  /// drawing one per particle stays a tight loop.
  double normal() {
    const uint64_t r = bits();
    // The layer and the signed 32-bit abscissa come from disjoint bits.
    const int layer = static_cast<int>(r & 127);
    const int64_t hz = static_cast<int32_t>(r >> 32);
    const uint64_t magnitude = static_cast<uint64_t>(hz < 0 ? -hz : hz);
    if (magnitude < zig_->k[layer]) return static_cast<double>(hz) * zig_->w[layer];
    const Tail tail = normalTail(hz, layer, *this);
    s_ = tail.state;
    return tail.value;
  }
  /// Zero-mean normal with standard deviation sigma (sigma <= 0 gives 0).
  double gaussian(double sigma) { return sigma > 0.0 ? sigma * normal() : 0.0; }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  // The rare case of normal(), out of line. It takes a copy of the stream
  // and returns the state it leaves, rather than taking `this`: a Random
  // whose address never escapes can live in registers, as one copied into
  // a local for a loop of draws does (a stream behind a pointer is stored
  // and reloaded around each draw when the loop also stores through a
  // char pointer).
  struct Tail {
    double value;
    std::array<uint64_t, 4> state;
  };
  static Tail normalTail(int64_t hz, int layer, Random stream);

  std::array<uint64_t, 4> s_;
  const ZigguratTables* zig_;
};

}  // namespace pf

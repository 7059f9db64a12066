#include "pf_localization/core/util/random.h"

#include <cmath>
#include <cstdlib>

namespace pf {
namespace {

// The ziggurat's 128 layers for the standard normal, built once: k are the
// acceptance bounds, w the scale from integer to x, f the density at each
// layer's edge (Marsaglia & Tsang 2000, with r = 3.442619855899 and layer
// area v = 9.91256303526217e-3).
struct Ziggurat : ZigguratTables {
  static constexpr double kR = 3.442619855899;

  Ziggurat() {
    constexpr double m = 2147483648.0;  // 2^31
    constexpr double v = 9.91256303526217e-3;
    double d = kR, t = kR;
    const double q = v / std::exp(-0.5 * d * d);
    k[0] = static_cast<uint32_t>((d / q) * m);
    k[1] = 0;
    w[0] = q / m;
    w[127] = d / m;
    f[0] = 1.0;
    f[127] = std::exp(-0.5 * d * d);
    for (int i = 126; i >= 1; --i) {
      d = std::sqrt(-2.0 * std::log(v / d + std::exp(-0.5 * d * d)));
      k[i + 1] = static_cast<uint32_t>((d / t) * m);
      t = d;
      f[i] = std::exp(-0.5 * d * d);
      w[i] = d / m;
    }
  }
};

const Ziggurat& ziggurat() {
  static const Ziggurat z;
  return z;
}

uint64_t splitmix64(uint64_t* x) {
  uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

Random::Random(uint64_t seed) : zig_(&ziggurat()) {
  // The tables are built now (the first Random), not inside the first update.
  for (uint64_t& word : s_) word = splitmix64(&seed);
}

Random::Tail Random::normalTail(int64_t hz, int layer, Random stream) {
  const Ziggurat& z = ziggurat();
  while (true) {
    const double x = static_cast<double>(hz) * z.w[layer];
    if (layer == 0) {
      // Beyond r: Marsaglia's exponential method for the normal tail.
      double tx, ty;
      do {
        tx = -std::log(1.0 - stream.uniform()) / Ziggurat::kR;
        ty = -std::log(1.0 - stream.uniform());
      } while (ty + ty < tx * tx);
      return {hz > 0 ? Ziggurat::kR + tx : -Ziggurat::kR - tx, stream.s_};
    }
    if (z.f[layer] + stream.uniform() * (z.f[layer - 1] - z.f[layer]) < std::exp(-0.5 * x * x)) {
      return {x, stream.s_};
    }
    const uint64_t r = stream.bits();
    layer = static_cast<int>(r & 127);
    hz = static_cast<int32_t>(r >> 32);
    if (static_cast<uint64_t>(std::llabs(hz)) < z.k[layer]) {
      return {static_cast<double>(hz) * z.w[layer], stream.s_};
    }
  }
}

}  // namespace pf

// Reads fuzzer bytes front to back as a small, stable structured format, so
// that a seed corpus can be written by hand (test/fuzz/make_corpus.py) and a
// crash input can be decoded by reading this file.
//
//   u8()        one byte (0 once the input is used up)
//   u16()       two bytes, little-endian
//   num(lo, hi) a selector byte, then:
//                 0 NaN, 1 +inf, 2 -inf, 3 0.0, 4 -1.0, 5 1e300, 6 -1e300,
//                 7 the smallest denormal, 8 the next 8 bytes as a raw
//                 little-endian IEEE double, 9 -(lo + (hi - lo) * u16 / 65535),
//                 10..255: lo + (hi - lo) * u16 / 65535.
//               Once the input is used up: (lo + hi) / 2.
// Ordinary values therefore cost three bytes (selector >= 10, then u16), and
// the interesting ones about 4% of selector values each.
//
// With PF_FUZZ_BOUNDED=1 in the environment every finite value keeps a sane
// magnitude: |v| <= 1e4 and |v| >= 1e-3 unless 0 (1e300 becomes 1e4, the
// denormal 1e-3). NaN and inf stay. Meant for fuzzing past the known
// overflow bugs (float -> integer casts of huge coordinates) while they are
// open; the default is unbounded.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

namespace pf_fuzz {

class Input {
 public:
  Input(const uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool exhausted() const { return pos_ >= size_; }
  std::size_t remaining() const { return exhausted() ? 0 : size_ - pos_; }

  uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }

  uint16_t u16() {
    const uint16_t lo = u8();
    const uint16_t hi = u8();
    return static_cast<uint16_t>(lo | (hi << 8));
  }

  static bool bounded() {
    static const bool b = [] {
      const char* e = std::getenv("PF_FUZZ_BOUNDED");
      return e && *e && *e != '0';
    }();
    return b;
  }

  double num(double lo, double hi) {
    const double v = numUnbounded(lo, hi);
    if (!bounded() || !std::isfinite(v) || v == 0.0) return v;
    const double m = std::fabs(v) > 1e4 ? 1e4 : std::fabs(v) < 1e-3 ? 1e-3 : std::fabs(v);
    return v < 0 ? -m : m;
  }

  double numUnbounded(double lo, double hi) {
    if (exhausted()) return 0.5 * (lo + hi);
    const uint8_t sel = u8();
    switch (sel) {
      case 0:
        return std::numeric_limits<double>::quiet_NaN();
      case 1:
        return std::numeric_limits<double>::infinity();
      case 2:
        return -std::numeric_limits<double>::infinity();
      case 3:
        return 0.0;
      case 4:
        return -1.0;
      case 5:
        return 1e300;
      case 6:
        return -1e300;
      case 7:
        return std::numeric_limits<double>::denorm_min();
      case 8: {
        uint64_t bits = 0;
        for (int i = 0; i < 8; ++i) bits |= static_cast<uint64_t>(u8()) << (8 * i);
        double v;
        std::memcpy(&v, &bits, sizeof v);
        return v;
      }
      case 9:
        return -(lo + (hi - lo) * u16() / 65535.0);
      default:
        return lo + (hi - lo) * u16() / 65535.0;
    }
  }

  /// Everything not read yet.
  std::string rest() {
    if (exhausted()) return {};
    std::string s(reinterpret_cast<const char*>(data_ + pos_), size_ - pos_);
    pos_ = size_;
    return s;
  }

 private:
  const uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace pf_fuzz

// An invariant of the core that does not hold: a finding, reported as a crash.
#define PF_FUZZ_CHECK(cond, ...)                                                    \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      std::fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
      std::fprintf(stderr, __VA_ARGS__);                                            \
      std::fprintf(stderr, "\n");                                                   \
      std::abort();                                                                 \
    }                                                                               \
  } while (0)

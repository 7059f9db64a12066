#include "pf_localization/core/util/packed_flags.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace pf {
namespace {

// Each packed answer against the plain compare, on every byte value and on
// 16-bit values near and far from the bounds.
TEST(PackedFlags, BytesInRangeAsComparedOneByOne) {
  std::mt19937 rng(3);
  std::vector<int8_t> values(64);
  for (int round = 0; round < 200; ++round) {
    for (int8_t& v : values) v = static_cast<int8_t>(rng() % 256);
    for (const auto& [lo, hi] :
         {std::pair{0u, 19u}, {65u, 127u}, {0u, 0u}, {0u, 127u}, {50u, 50u}}) {
      uint64_t expected = 0;
      for (int k = 0; k < 64; ++k) {
        if (values[k] >= static_cast<int>(lo) && values[k] <= static_cast<int>(hi)) {
          expected |= uint64_t{1} << k;
        }
      }
      ASSERT_EQ(expected, flagsInRange(values.data(), lo, hi)) << lo << ".." << hi;
    }
  }
}

TEST(PackedFlags, LanesBelowAsComparedOneByOne) {
  std::mt19937 rng(5);
  std::vector<uint16_t> values(64);
  for (int round = 0; round < 200; ++round) {
    for (uint16_t& v : values) v = static_cast<uint16_t>(round % 2 ? rng() % 65536 : rng() % 8);
    for (unsigned bound : {0u, 1u, 3u, 7u, 1000u, 0x7fffu, 0x8000u}) {
      uint64_t expected = 0;
      for (int k = 0; k < 64; ++k) {
        if (values[k] < bound) expected |= uint64_t{1} << k;
      }
      ASSERT_EQ(expected, flagsBelow(values.data(), bound)) << bound;
    }
  }
}

}  // namespace
}  // namespace pf

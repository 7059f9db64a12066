// Flags of 64 consecutive small values, as the bits of one 64-bit word, a
// few values at a time in a register ("SIMD within a register": H. S.
// Warren, Hacker's Delight, 2nd ed. 2012, ch. 6, searching words for a
// byte in a range). Map set-up asks such questions of every cell of a grid
// (free? occupied? near an obstacle?); a compare, shift and or a cell cost
// more than the rest of some of those passes.
#pragma once

#include <cstdint>
#include <cstring>

namespace pf {

/// Bit k set where byte k of `bytes` (unsigned) is at most `max` (<= 127).
inline uint64_t bytesAtMost(uint64_t bytes, unsigned max) {
  constexpr uint64_t kHigh = 0x8080808080808080ull, kOnes = 0x0101010101010101ull;
  // (b | 0x80) - (max + 1) keeps each byte's borrow to itself and sets its
  // top bit where b & 0x7f > max; b <= max where neither that bit nor b's
  // own is set. The multiply gathers the bytes' flags into the top byte.
  const uint64_t over = (bytes | kHigh) - kOnes * (max + 1);
  const uint64_t flags = (~bytes & ~over & kHigh) >> 7;
  return (flags * 0x0102040810204080ull) >> 56;
}

/// Bit k set where 16-bit lane k of `lanes` is below `bound` (<= 0x8000).
inline uint64_t lanesBelow(uint64_t lanes, unsigned bound) {
  constexpr uint64_t kHigh = 0x8000800080008000ull, kOnes = 0x0001000100010001ull;
  const uint64_t over = (lanes | kHigh) - kOnes * bound;
  const uint64_t flags = (~lanes & ~over & kHigh) >> 15;
  // Lane k's flag (bit 16 k) lands on bit 60 + k.
  return (flags * ((1ull << 15) | (1ull << 30) | (1ull << 45) | (1ull << 60))) >> 60;
}

/// Bit k set where values[k] (k < 64) is in [lo, hi], 0 <= lo <= hi <= 127.
inline uint64_t flagsInRange(const int8_t* values, unsigned lo, unsigned hi) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "value 0 is a word's lowest byte");
  uint64_t out = 0;
  for (int k = 0; k < 8; ++k) {
    uint64_t x;
    std::memcpy(&x, values + 8 * k, sizeof x);
    const uint64_t in = bytesAtMost(x, hi) & (lo == 0 ? ~0ull : ~bytesAtMost(x, lo - 1));
    out |= in << (8 * k);
  }
  return out;
}

/// Bit k set where values[k] (k < 64) is below `bound` (<= 0x8000).
inline uint64_t flagsBelow(const uint16_t* values, unsigned bound) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "value 0 is a word's lowest lane");
  uint64_t out = 0;
  for (int k = 0; k < 16; ++k) {
    uint64_t x;
    std::memcpy(&x, values + 4 * k, sizeof x);
    out |= lanesBelow(x, bound) << (4 * k);
  }
  return out;
}

}  // namespace pf

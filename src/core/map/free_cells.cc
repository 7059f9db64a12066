#include "pf_localization/core/map/free_cells.h"

#include <algorithm>
#include <cstring>

namespace pf {

FreeCells FreeCells::ofValues(const int8_t* values, std::size_t cells, int8_t free_max) {
  FreeCells out;
  out.words_.assign((cells + 63) / 64, 0);
  constexpr uint64_t kHigh = 0x8080808080808080ull, kOnes = 0x0101010101010101ull;
  const uint64_t above = kOnes * static_cast<uint64_t>(free_max + 1);
  // Eight values in a word: (v | 0x80) - (free_max + 1) keeps each byte's
  // borrow to itself and sets its top bit where v & 0x7f > free_max; a
  // value in range has neither that bit nor its own (a negative) set. The
  // multiply gathers the bytes' flags into the top byte, value 0 lowest.
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "value 0 is a word's lowest byte");
  const auto eight = [&](const int8_t* v) {
    uint64_t x;
    std::memcpy(&x, v, sizeof x);
    const uint64_t flags = (~x & ~((x | kHigh) - above) & kHigh) >> 7;
    return (flags * 0x0102040810204080ull) >> 56;
  };
  const std::size_t whole = cells / 64;
  for (std::size_t w = 0; w < whole; ++w) {
    uint64_t word = 0;
    for (int k = 0; k < 8; ++k) word |= eight(values + w * 64 + 8 * k) << (8 * k);
    out.words_[w] = word;
  }
  for (std::size_t i = whole * 64; i < cells; ++i) {
    if (values[i] >= 0 && values[i] <= free_max) out.words_[i / 64] |= uint64_t{1} << (i % 64);
  }
  out.countBefore();
  return out;
}

void FreeCells::countBefore() {
  before_.resize(words_.size());
  std::size_t count = 0;
  for (std::size_t w = 0; w < words_.size(); ++w) {
    before_[w] = static_cast<uint32_t>(count);
    count += static_cast<std::size_t>(__builtin_popcountll(words_[w]));
  }
  size_ = count;
}

int FreeCells::operator[](std::size_t k) const {
  // The last word with fewer than k + 1 free cells before it holds the cell.
  const auto after = std::upper_bound(before_.begin(), before_.end(), static_cast<uint32_t>(k));
  const std::size_t w = static_cast<std::size_t>(after - before_.begin()) - 1;
  uint64_t bits = words_[w];
  for (std::size_t skip = k - before_[w]; skip > 0; --skip) bits &= bits - 1;
  return static_cast<int>(w * 64 + static_cast<std::size_t>(__builtin_ctzll(bits)));
}

}  // namespace pf

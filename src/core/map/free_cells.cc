#include "pf_localization/core/map/free_cells.h"

#include <algorithm>

#include "pf_localization/core/util/packed_flags.h"

namespace pf {

FreeCells FreeCells::ofValues(const int8_t* values, std::size_t cells, int8_t free_max) {
  FreeCells out;
  out.words_.assign((cells + 63) / 64, 0);
  const auto max = static_cast<unsigned>(free_max);
  const std::size_t whole = cells / 64;
  for (std::size_t w = 0; w < whole; ++w) out.words_[w] = flagsInRange(values + 64 * w, 0, max);
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

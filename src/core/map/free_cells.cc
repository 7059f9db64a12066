#include "pf_localization/core/map/free_cells.h"

#include <algorithm>

namespace pf {

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

// Dense ids for the occupied bins of an (x, y, yaw) histogram, and the bin
// of a coordinate (binIndex).
//
// The clustering and KLD-sampling bin every particle on every update. A
// node-based hash map allocates once per new bin, so a wide cloud (global
// localization, recovery) left the process's heap fragmented and its memory
// higher for good. This is an open-addressing table whose storage is kept
// between updates: after the widest cloud it has seen, it allocates nothing.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

namespace pf {

class BinTable {
 public:
  /// Packs three bin indices (each clamped to +-2^20) into one key.
  static uint64_t key(int64_t x, int64_t y, int64_t yaw) {
    return (field(x) << 42) | (field(y) << 21) | field(yaw);
  }

  /// The three bin indices of a key, as clamped by key().
  struct Bin {
    int64_t x, y, yaw;
  };
  static Bin unpack(uint64_t key) {
    constexpr uint64_t kField = (uint64_t{1} << 21) - 1;
    return {static_cast<int64_t>((key >> 42) & kField) - kHalfRange,
            static_cast<int64_t>((key >> 21) & kField) - kHalfRange,
            static_cast<int64_t>(key & kField) - kHalfRange};
  }

  /// Empties the table, with room for `expected` bins.
  void reset(std::size_t expected) {
    std::size_t capacity = 16;
    while (capacity < 2 * expected) capacity *= 2;
    if (capacity == mask_ + 1) {
      // The same size as last time: only the slots in use need emptying, a
      // few dozen for a tracking cloud instead of twice the particle count.
      for (std::size_t i : used_) slots_[i].key = kEmpty;
    } else {
      if (slots_.size() < capacity) slots_.resize(capacity);
      mask_ = capacity - 1;
      for (std::size_t i = 0; i <= mask_; ++i) slots_[i].key = kEmpty;
    }
    used_.clear();
    size_ = 0;
  }

  /// The id of `key`, 0, 1, 2, ... in order of first insertion.
  int insert(uint64_t key) {
    std::size_t i = slot(key);
    while (slots_[i].key != kEmpty) {
      if (slots_[i].key == key) return slots_[i].id;
      i = (i + 1) & mask_;
    }
    slots_[i] = {key, static_cast<int>(size_)};
    used_.push_back(i);
    return static_cast<int>(size_++);
  }

  /// The id of `key`, or -1 when absent.
  int find(uint64_t key) const {
    for (std::size_t i = slot(key); slots_[i].key != kEmpty; i = (i + 1) & mask_) {
      if (slots_[i].key == key) return slots_[i].id;
    }
    return -1;
  }

  std::size_t size() const { return size_; }

 private:
  // Keys use 63 bits, so all ones never occurs.
  static constexpr uint64_t kEmpty = ~uint64_t{0};
  static constexpr int64_t kHalfRange = int64_t{1} << 20;

  struct Slot {
    uint64_t key;
    int id;
  };

  static uint64_t field(int64_t v) {
    const int64_t clamped = v < -kHalfRange ? -kHalfRange : (v >= kHalfRange ? kHalfRange - 1 : v);
    return static_cast<uint64_t>(clamped + kHalfRange);
  }

  std::size_t slot(uint64_t key) const {
    // splitmix64's finaliser: neighbouring bins must land far apart.
    key = (key ^ (key >> 30)) * 0xbf58476d1ce4e5b9ULL;
    key = (key ^ (key >> 27)) * 0x94d049bb133111ebULL;
    return static_cast<std::size_t>(key ^ (key >> 31)) & mask_;
  }

  std::vector<Slot> slots_;
  std::vector<std::size_t> used_;  // the slots filled since the last reset
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

// The histogram bin of a coordinate, safe for any double.
//
// Converting a double outside the integer range (or NaN) to an integer is
// undefined behaviour, and particles can end up anywhere. Bins are clamped to +-2^52, far beyond
// any real map, and NaN goes to bin 0.
inline int64_t binIndex(double value, double bin_size) {
  constexpr double kLimit = 4503599627370496.0;  // 2^52
  const double bin = std::floor(value / bin_size);
  if (!(bin > -kLimit)) return std::isnan(bin) ? 0 : -static_cast<int64_t>(kLimit);
  if (!(bin < kLimit)) return static_cast<int64_t>(kLimit);
  return static_cast<int64_t>(bin);
}

}  // namespace pf

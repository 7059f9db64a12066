// The likelihood field's per-cell tables, one for each range_max in use.
//
// A beam's log p = log(z_hit N(d; 0, sigma_hit) + z_rand / range_max)
// depends on the sensor's range_max, so a robot whose lidars differ in it (a
// long-range front lidar and a short-range rear one, each update scoring
// both) needs a table for each. Holding one table and rebuilding it whenever
// the range_max changed rebuilt it twice per update: on the bundled
// warehouse map 27 ms an update instead of 1.4. Tables are built on first use
// and kept for up to kMaxTables values of range_max; past that, the one used
// longest ago is rebuilt for the new value.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace pf {

class LikelihoodTables {
 public:
  static constexpr std::size_t kMaxTables = 4;
  /// Fills `table` (whatever it held) for `range_max`.
  using Build = std::function<void(double range_max, std::vector<float>* table)>;

  /// The table for `range_max`, built with `build` when none is held. Valid
  /// until the next call.
  const std::vector<float>& get(double range_max, const Build& build);
  /// Tables built so far.
  std::size_t builds() const { return builds_; }

 private:
  struct Entry {
    double range_max;
    std::vector<float> table;
    uint64_t used;  // the value of uses_ when last returned
  };
  std::vector<Entry> entries_;
  uint64_t uses_ = 0;
  std::size_t builds_ = 0;
};

}  // namespace pf

#include "pf_localization/core/sensor/likelihood_tables.h"

#include <algorithm>

namespace pf {

const std::vector<float>& LikelihoodTables::get(double range_max, const Build& build) {
  ++uses_;
  for (Entry& e : entries_) {
    if (e.range_max == range_max) {
      e.used = uses_;
      return e.table;
    }
  }
  Entry* entry;
  if (entries_.size() < kMaxTables) {
    entry = &entries_.emplace_back(Entry{range_max, {}, uses_});
  } else {
    entry = &*std::min_element(entries_.begin(), entries_.end(),
                               [](const Entry& a, const Entry& b) { return a.used < b.used; });
    *entry = Entry{range_max, std::move(entry->table), uses_};
  }
  build(range_max, &entry->table);
  ++builds_;
  return entry->table;
}

}  // namespace pf

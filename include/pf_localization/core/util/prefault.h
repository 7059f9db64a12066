// Storage that is written once when it is reserved, so that the update path
// neither allocates nor touches fresh pages (the kernel backs untouched pages
// lazily: reserving alone let a process's resident memory creep up hours
// into a run; see docs/design.md, "Storage is prefaulted").
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace pf {

/// Grows `v` to at least `n` elements and back to its size: the capacity,
/// and the pages behind it, stay; the contents are kept.
template <typename T>
void prefault(std::vector<T>* v, std::size_t n) {
  const std::size_t size = v->size();
  v->resize(std::max(n, size));
  v->resize(size);
}

}  // namespace pf

// Working storage of the update path, which allocates nothing once the
// widest cloud has been seen:
//  - threadScratch: storage kept between calls, one per thread, for the
//    per-particle loops. Not a plain thread_local: in a shared library every
//    access to one is a call (__tls_get_addr), repeated on every use inside a
//    loop; the address a function returns that the compiler may not look
//    into is computed once.
//  - prefault: storage written once when it is reserved, so that the update
//    path touches no fresh page either (see docs/design.md, "Storage is
//    prefaulted").
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace pf {

/// This thread's T (value-initialised on the thread's first call).
template <typename T>
__attribute__((noipa)) T& threadScratch() {
  thread_local T storage{};
  return storage;
}

/// Grows `v` to at least `n` elements and back to its size: the capacity,
/// and the pages behind it, stay; the contents are kept.
template <typename T>
void prefault(std::vector<T>* v, std::size_t n) {
  const std::size_t size = v->size();
  v->resize(std::max(n, size));
  v->resize(size);
}

}  // namespace pf

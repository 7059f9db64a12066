// Working storage kept between calls, one per thread, for the per-particle
// loops of the filter update (they allocate nothing once the widest cloud
// has been seen).
//
// Not a plain thread_local: in a shared library every access to one is a
// call (__tls_get_addr), and the compiler repeats it on every use inside a
// loop, even through a reference. The address returned by a function it may
// not look into is computed once.
#pragma once

namespace pf {

/// This thread's T (value-initialised on the thread's first call).
template <typename T>
__attribute__((noipa)) T& threadScratch() {
  thread_local T storage{};
  return storage;
}

}  // namespace pf

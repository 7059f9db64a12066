// Test support: the message of the exception a piece of code throws, for the
// tests that check that an error names what is wrong.
#pragma once

#include <exception>
#include <functional>
#include <string>

namespace pf::test {

/// What `f` says when it throws an E (or a type derived from it); "" when it
/// throws nothing. Any other exception passes through (and fails the test).
template <typename E = std::exception>
std::string whatOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

}  // namespace pf::test

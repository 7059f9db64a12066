// The one way the core refuses a parameter: std::invalid_argument with the
// message "invalid parameter NAME = VALUE: must be RANGE", which pf_node
// prints as it is when it refuses to start, so every module's limits read alike.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace pf {

/// Throws std::invalid_argument naming `name`, `value` and the valid `range` unless `ok`.
inline void requireParameter(bool ok, const std::string& name, const std::string& range,
                             double value) {
  if (!ok) {
    std::ostringstream text;  // shortest form: 500, not 500.000000
    text << "invalid parameter " << name << " = " << value << ": must be " << range;
    throw std::invalid_argument(text.str());
  }
}

}  // namespace pf

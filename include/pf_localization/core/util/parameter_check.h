// A check that a parameter table's range cannot say alone (one value against
// another, a sum), worded as the tables word theirs: std::invalid_argument
// with "invalid parameter NAME = VALUE: must be RANGE" (parameter_table.h),
// which pf_node prints as it is when it refuses to start.
#pragma once

#include <stdexcept>
#include <string>

#include "pf_localization/core/util/parameter_table.h"

namespace pf {

/// Throws std::invalid_argument naming `name`, `value` and the valid `range` unless `ok`.
inline void requireParameter(bool ok, const std::string& name, const std::string& range,
                             double value) {
  if (!ok) throw std::invalid_argument(invalidParameterMessage(name, formatNumber(value), range));
}

}  // namespace pf

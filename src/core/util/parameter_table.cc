#include "pf_localization/core/util/parameter_table.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace pf {

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  const bool above_min = min_open ? v > min : v >= min;
  const bool below_max = max_open ? v < max : v <= max;
  return above_min && below_max;
}

std::string Range::text() const {
  const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
  if (has_min && has_max) {
    return std::string("in ") + (min_open ? "(" : "[") + formatNumber(min) + ", " +
           formatNumber(max) + (max_open ? ")" : "]");
  }
  if (has_min) return (min_open ? "> " : ">= ") + formatNumber(min);
  if (has_max) return (max_open ? "< " : "<= ") + formatNumber(max);
  return "finite";
}

std::string formatNumber(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

std::string allowedText(const ParamInfo& info) {
  if (!info.choices.empty()) {
    std::string words;
    for (std::size_t i = 0; i < info.choices.size(); ++i) {
      words += (i == 0 ? "" : i + 1 == info.choices.size() ? " or " : ", ") + info.choices[i];
    }
    return words;
  }
  std::string text = info.range.text();
  std::string in_brackets = info.unit;
  if (!info.note.empty()) in_brackets += (in_brackets.empty() ? "" : "; ") + info.note;
  if (!in_brackets.empty()) text += " (" + in_brackets + ")";
  return text;
}

std::string invalidParameterMessage(const std::string& name, const std::string& value,
                                    const std::string& must_be) {
  return "invalid parameter " + name + " = " + value + ": must be " + must_be;
}

void checkValue(const ParamInfo& info, double value) {
  if (info.range.contains(value) || (info.unset_allowed && std::isnan(value))) return;
  throw std::invalid_argument(
      invalidParameterMessage(info.name, formatNumber(value), allowedText(info)));
}

void checkValue(const ParamInfo& info, const std::string& value) {
  if (info.choices.empty()) {
    if (!value.empty() || info.unset_allowed) return;
    throw std::invalid_argument(invalidParameterMessage(info.name, "''", "a non-empty name"));
  }
  for (const std::string& c : info.choices) {
    if (c == value) return;
  }
  throw std::invalid_argument(
      invalidParameterMessage(info.name, "'" + value + "'", allowedText(info)));
}

}  // namespace pf

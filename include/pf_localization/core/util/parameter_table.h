// One declaration per parameter, beside the options struct it fills: its
// name, unit, one-line description, valid range, whether it may change while
// the filter runs, and amcl's name for it. Reading (ros/params/localizer_config.h),
// checking (checkRanges), live reconfiguration (ros/live_params.h), the
// diagnostics, `pf_node --help` and the generated files (config/pf.yaml,
// cfg/PfLocalization.cfg, the README's table: ros/parameter_docs.h) all walk
// these tables, so a parameter cannot mean one thing in one place and another
// elsewhere. The default is the struct member's initialiser: a
// default-constructed options struct holds every default.
//
// Modelled on Cartographer's options (one commented field each, created
// beside the class) and Beluga's one declaration per ROS parameter.
#pragma once

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace pf {

/// The values a number may take: an interval, each end closed or open, or
/// unbounded. NaN is never in range.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;
  bool max_open = false;

  static Range any() { return {}; }  // any finite number
  static Range atLeast(double v) { return {v, kInf, false, false}; }
  static Range above(double v) { return {v, kInf, true, false}; }
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range closedOpen(double lo, double hi) { return {lo, hi, false, true}; }
  static Range openClosed(double lo, double hi) { return {lo, hi, true, false}; }
  static Range open(double lo, double hi) { return {lo, hi, true, true}; }

  /// Finite and within the bounds.
  bool contains(double v) const;
  /// ">= 0", "> 0", "in [0, 1)", "finite".
  std::string text() const;

  static constexpr double kInf = std::numeric_limits<double>::infinity();
};

/// What a parameter is to amcl: ours only, the same name in amcl, or amcl's
/// other name for it (ParamInfo::amcl_name).
enum class Amcl { kOursOnly, kSameName, kAlias };

/// Everything about a parameter except where its value lives. Declared as
///   ParamInfo("laser_sigma_hit", "m", "std dev of the hit component")
///       .in(Range::above(0)).amcl().live(0, 10)
struct ParamInfo {
  ParamInfo(std::string name, std::string unit, std::string description)
      : name(std::move(name)), unit(std::move(unit)), description(std::move(description)) {}

  /// Valid values of a number (ints are checked as numbers).
  ParamInfo& in(Range r) { return range = r, *this; }
  /// May change while running; a number's reconfigure sliders go from lo to hi
  /// (a client clamps to them before the node sees a value).
  ParamInfo& live(double lo = 0.0, double hi = 0.0) {
    return is_live = true, slider_min = lo, slider_max = hi, *this;
  }
  /// amcl has this parameter, under the same name.
  ParamInfo& amcl() { return amcl_kind = Amcl::kSameName, *this; }
  /// amcl has it under `other` (odom_frame_id for odom_frame).
  ParamInfo& amclAlias(std::string other) {
    return amcl_kind = Amcl::kAlias, amcl_name = std::move(other), *this;
  }
  /// A string with a fixed vocabulary.
  ParamInfo& oneOf(std::vector<std::string> words) { return choices = std::move(words), *this; }
  /// How to read special values, appended to the range in messages ("0: off").
  ParamInfo& withNote(std::string text) { return note = std::move(text), *this; }
  /// A number that may also be unset (NaN or absent), or a text that may be
  /// empty, which means `meaning`.
  ParamInfo& unsetMeans(std::string meaning) {
    note += (note.empty() ? "unset: " : "; unset: ") + std::move(meaning);
    return unset_allowed = true, *this;
  }

  std::string name;
  std::string unit;         // "m", "rad", "Hz", "particles"; empty: none
  std::string description;  // one line: what it does
  Range range;
  bool is_live = false;
  Amcl amcl_kind = Amcl::kOursOnly;
  std::string amcl_name;             // with Amcl::kAlias
  std::vector<std::string> choices;  // empty: any non-empty text
  std::string note;
  bool unset_allowed = false;  // NaN is in range; a text may be empty
  double slider_min = 0.0;
  double slider_max = 0.0;
  std::string group;  // the section it is listed in (config/pf.yaml, the .cfg's groups)
};

/// How a table reaches one value of type T inside Options.
template <class Options, class T>
struct Field {
  std::function<T(const Options&)> get;
  std::function<void(Options&, const T&)> set;
};

template <class Options>
using AnyField = std::variant<Field<Options, double>, Field<Options, int>, Field<Options, bool>,
                              Field<Options, std::string>>;

template <class Options>
struct Parameter {
  ParamInfo info;
  AnyField<Options> field;
};

template <class Options>
using ParameterTable = std::vector<Parameter<Options>>;

/// A row for a plain member of Options.
template <class Options, class T>
Parameter<Options> member(T Options::*m, ParamInfo info) {
  Field<Options, T> f{[m](const Options& o) { return o.*m; },
                      [m](Options& o, const T& v) { o.*m = v; }};
  return {std::move(info), AnyField<Options>(std::move(f))};
}

/// A row whose value is computed (an enum spelt as words, an optional pose).
template <class Options, class T>
Parameter<Options> computed(std::function<T(const Options&)> get,
                            std::function<void(Options&, const T&)> set, ParamInfo info) {
  return {std::move(info), AnyField<Options>(Field<Options, T>{std::move(get), std::move(set)})};
}

/// `inner`'s rows as rows of Outer, through Outer's member `m`.
template <class Outer, class Inner>
ParameterTable<Outer> nested(Inner Outer::*m, const ParameterTable<Inner>& inner) {
  ParameterTable<Outer> out;
  out.reserve(inner.size());
  for (const Parameter<Inner>& p : inner) {
    out.push_back({p.info, std::visit(
                               [m](const auto& f) -> AnyField<Outer> {
                                 using T = decltype(f.get(std::declval<const Inner&>()));
                                 return Field<Outer, T>{
                                     [m, get = f.get](const Outer& o) { return get(o.*m); },
                                     [m, set = f.set](Outer& o, const T& v) { set(o.*m, v); }};
                               },
                               p.field)});
  }
  return out;
}

/// Appends `more` to `table`, listed under `group`.
template <class Options>
void append(ParameterTable<Options>* table, ParameterTable<Options> more,
            const std::string& group) {
  for (Parameter<Options>& p : more) p.info.group = group;
  table->insert(table->end(), more.begin(), more.end());
}

/// The row named `name`, or nullptr.
template <class Options>
const Parameter<Options>* findParameter(const ParameterTable<Options>& table,
                                        const std::string& name) {
  for (const Parameter<Options>& p : table) {
    if (p.info.name == name) return &p;
  }
  return nullptr;
}

/// The one message of a refused value: "invalid parameter NAME = VALUE: must
/// be RANGE (UNIT)". VALUE in its shortest form.
std::string invalidParameterMessage(const std::string& name, const std::string& value,
                                    const std::string& must_be);
/// What `info` allows, as the message says it: "> 0 (m)", "in [0, 1]",
/// "finite (Hz; <= 0: no limit)", "first_beam or last_beam".
std::string allowedText(const ParamInfo& info);
/// A number in the shortest form that reads back as the same double.
std::string formatNumber(double v);

/// Throws std::invalid_argument with invalidParameterMessage unless `value`
/// is allowed by `info`.
void checkValue(const ParamInfo& info, double value);
void checkValue(const ParamInfo& info, const std::string& value);
inline void checkValue(const ParamInfo&, bool) {}

/// Checks every row of `table` against `options`, in the table's order.
template <class Options>
void checkRanges(const ParameterTable<Options>& table, const Options& options) {
  for (const Parameter<Options>& p : table) {
    std::visit(
        [&](const auto& f) {
          const auto v = f.get(options);
          if constexpr (std::is_same_v<decltype(v), const int>) {
            checkValue(p.info, static_cast<double>(v));
          } else {
            checkValue(p.info, v);
          }
        },
        p.field);
  }
}

// A check that a parameter table's range cannot say alone (one value against
// another, a sum), worded as the tables word theirs: std::invalid_argument
// with "invalid parameter NAME = VALUE: must be RANGE",
// which pf_node prints as it is when it refuses to start.
/// Throws std::invalid_argument naming `name`, `value` and the valid `range` unless `ok`.
inline void requireParameter(bool ok, const std::string& name, const std::string& range,
                             double value) {
  if (!ok) throw std::invalid_argument(invalidParameterMessage(name, formatNumber(value), range));
}

}  // namespace pf

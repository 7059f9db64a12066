#include "pf_localization/ros/params/live_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/ros/params/amcl_params.h"

namespace pf_ros {
namespace {

using Row = pf::Parameter<LocalizerConfig>;

// The rows of localizerParameters() that may change while running, in its
// order (which the log lines follow).
const std::vector<const Row*>& liveParams() {
  static const std::vector<const Row*> rows = [] {
    std::vector<const Row*> live;
    for (const Row& p : localizerParameters()) {
      if (p.info.is_live) live.push_back(&p);
    }
    return live;
  }();
  return rows;
}

// A value as the log line of a change shows it: six digits are enough to see
// what changed (the error messages give the exact value).
std::string show(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}
std::string show(int value) { return std::to_string(value); }
std::string show(bool value) { return value ? "true" : "false"; }
std::string show(const std::string& value) { return value; }

// The kld_z that kld_confidence p stands for (p = Phi(z)).
double kldZOf(double p) { return p > 0.0 && p < 1.0 ? pf::normalQuantile(p) : 0.0; }

template <typename Param>
const Param* find(const std::vector<Param>& params, const std::string& name) {
  for (const Param& p : params) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

}  // namespace

std::vector<std::string> liveParamNames() {
  std::vector<std::string> names;
  for (const Row* p : liveParams()) names.push_back(p->info.name);
  return names;
}

namespace {

template <typename Value, typename T>
void add(std::vector<Value>* values, const std::string& name, const T& value) {
  values->emplace_back();
  values->back().name = name;
  values->back().value = value;
}

}  // namespace

dynamic_reconfigure::Config liveParamsMessage(const LocalizerConfig& c) {
  dynamic_reconfigure::Config msg;
  for (const Row* p : liveParams()) {
    std::visit(
        [&](const auto& f) {
          const auto v = f.get(c);
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, double>) add(&msg.doubles, p->info.name, v);
          if constexpr (std::is_same_v<T, int>) add(&msg.ints, p->info.name, v);
          if constexpr (std::is_same_v<T, bool>) add(&msg.bools, p->info.name, v);
          if constexpr (std::is_same_v<T, std::string>) add(&msg.strs, p->info.name, v);
        },
        p->field);
  }
  add(&msg.doubles, "kld_z", kldZOf(c.filter.kld.confidence));
  add(&msg.bools, "restore_defaults", false);
  return msg;
}

void copyLiveParams(const LocalizerConfig& from, LocalizerConfig* to) {
  for (const Row* p : liveParams()) {
    std::visit([&](const auto& f) { f.set(*to, f.get(from)); }, p->field);
  }
}

namespace {

// Sets the row `p` of `next` from the request's value of that name, if any.
void takeRequested(const Row& p, const dynamic_reconfigure::Config& request,
                   LocalizerConfig* next) {
  std::visit(
      [&](const auto& f) {
        using T = std::decay_t<decltype(f.get(*next))>;
        const auto* values = [&request]() {
          if constexpr (std::is_same_v<T, double>) return &request.doubles;
          if constexpr (std::is_same_v<T, int>) return &request.ints;
          if constexpr (std::is_same_v<T, bool>) return &request.bools;
          if constexpr (std::is_same_v<T, std::string>) return &request.strs;
        }();
        if (const auto* v = find(*values, p.info.name)) f.set(*next, static_cast<T>(v->value));
      },
      p.field);
}

}  // namespace

LiveChange applyLiveParams(const LocalizerConfig& current,
                           const dynamic_reconfigure::Config& request) {
  LiveChange out{current, {}, ""};
  LocalizerConfig& next = out.config;
  for (const Row* p : liveParams()) takeRequested(*p, request, &next);
  // amcl's kld_z: taken when it moved and kld_confidence did not (a client
  // that only knows amcl's name), as readConfig takes it when ours is absent.
  const auto* z = find(request.doubles, "kld_z");
  const double z_was = kldZOf(current.filter.kld.confidence);
  std::string from_kld_z;
  if (z != nullptr && next.filter.kld.confidence == current.filter.kld.confidence &&
      std::fabs(z->value - z_was) > 1e-9 * std::max(1.0, std::fabs(z_was))) {
    const double p = kldConfidenceFromZ(z->value);
    if (!(std::isfinite(z->value) && p > 0.0 && p < 1.0)) {
      out.error = pf::invalidParameterMessage("kld_z", show(z->value),
                                              "a finite normal quantile between -8 and 8");
      return out;
    }
    next.filter.kld.confidence = p;
    from_kld_z = " (amcl's kld_z " + show(z_was) + " -> " + show(z->value) + ")";
  }
  // amcl spells "use the scan's own limit" as -1, as at start-up.
  next.filter.sensor.range_min = std::max(next.filter.sensor.range_min, 0.0);
  next.filter.sensor.range_max = std::max(next.filter.sensor.range_max, 0.0);

  // What changed, as it will be in effect.
  for (const Row* p : liveParams()) {
    std::visit(
        [&](const auto& f) {
          if (f.get(next) == f.get(current)) return;
          out.changed.push_back(p->info.name + " " + show(f.get(current)) + " -> " +
                                show(f.get(next)) +
                                (p->info.name == "kld_confidence" ? from_kld_z : ""));
        },
        p->field);
  }
  try {
    validate(next);
  } catch (const std::invalid_argument& e) {
    out.error = e.what();
  }
  return out;
}

}  // namespace pf_ros

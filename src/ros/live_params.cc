#include "pf_localization/ros/live_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "pf_localization/core/resampler.h"
#include "pf_localization/ros/amcl_params.h"

namespace pf_ros {
namespace {

template <typename T>
using Field = T& (*)(LocalizerConfig&);

// Only to name the type of a lambda's conversion in the table below.
template <typename T>
Field<T> field(Field<T> f) {
  return f;
}

struct LiveParam {
  const char* name;
  std::variant<Field<double>, Field<int>, Field<bool>> field;
};

// In cfg/PfLocalization.cfg's order (which the log lines follow); the unit
// test checks that the two list the same names and defaults.
const std::vector<LiveParam>& liveParams() {
  static const std::vector<LiveParam> params = {
      {"odom_alpha1",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.motion.alpha1; })},
      {"odom_alpha2",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.motion.alpha2; })},
      {"odom_alpha3",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.motion.alpha3; })},
      {"odom_alpha4",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.motion.alpha4; })},
      {"odom_alpha5",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.motion.alpha5; })},
      {"odom_fault_fraction",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.motion.fault_fraction; })},
      {"odom_fault_fraction_max", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.motion.fault_fraction_max;
       })},
      {"odom_fault_suspect_fraction", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.motion.fault_suspect_fraction;
       })},
      {"odom_fault_margin",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.motion.fault_margin; })},
      {"odom_jump_limit",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.odom_jump_limit; })},
      {"laser_z_hit",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.sensor.z_hit; })},
      {"laser_z_rand",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.sensor.z_rand; })},
      {"laser_sigma_hit",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.sensor.sigma_hit; })},
      {"laser_likelihood_max_dist",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.sensor.max_distance; })},
      {"laser_likelihood_exponent", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.sensor.likelihood_exponent;
       })},
      {"laser_z_short",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.beam.z_short; })},
      {"laser_z_max",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.beam.z_max; })},
      {"laser_lambda_short",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.beam.lambda_short; })},
      {"do_beamskip",
       field<bool>([](LocalizerConfig& c) -> bool& { return c.filter.sensor.beam_skip; })},
      {"beam_skip_distance", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.sensor.beam_skip_distance;
       })},
      {"beam_skip_threshold", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.sensor.beam_skip_threshold;
       })},
      {"beam_skip_error_threshold", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.sensor.beam_skip_error_threshold;
       })},
      {"laser_max_beams",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.sensor.max_beams; })},
      {"laser_min_range",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.sensor.range_min; })},
      {"laser_max_range",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.sensor.range_max; })},
      {"min_particles",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.kld.min_particles; })},
      {"max_particles",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.kld.max_particles; })},
      {"kld_err",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.kld.kld_err; })},
      {"kld_confidence",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.kld.confidence; })},
      {"kld_bin_xy",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.kld.bin_xy; })},
      {"kld_bin_yaw",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.kld.bin_yaw; })},
      {"update_min_d",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.update_min_d; })},
      {"update_min_a",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.update_min_a; })},
      {"update_fit_drop",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.update_fit_drop; })},
      {"update_fit_distance",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.update_fit_distance; })},
      {"resample_ess_fraction",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.resample_ess_fraction; })},
      {"tempering_ess_fraction", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.tempering_ess_fraction;
       })},
      {"tempering_ess_fraction_uncertain", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.tempering_ess_fraction_uncertain;
       })},
      {"cluster_xy",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.clusters.cell_xy; })},
      {"cluster_yaw",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.clusters.cell_yaw; })},
      {"cluster_join_weight_ratio", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.clusters.join_weight_ratio;
       })},
      {"recovery_alpha_slow",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.recovery.alpha_slow; })},
      {"recovery_alpha_fast",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.recovery.alpha_fast; })},
      {"recovery_trigger_ratio", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.recovery.trigger_ratio;
       })},
      {"recovery_patience",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.recovery.patience; })},
      {"recovery_patience_localized",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.recovery.patience_localized; })},
      {"recovery_lost_share",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.recovery.lost_share; })},
      {"recovery_kidnap_prior",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.recovery.kidnap_prior; })},
      {"recovery_expansion_ratio", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.recovery.expansion_ratio;
       })},
      {"recovery_expansion_std_xy", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.recovery.expansion_std_xy;
       })},
      {"recovery_expansion_std_yaw", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.recovery.expansion_std_yaw;
       })},
      {"confidence_hit_distance", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.confidence.hit_distance;
       })},
      {"confidence_lost_hit_fraction", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.confidence.lost_hit_fraction;
       })},
      {"confidence_localized_hit_fraction", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.confidence.localized_hit_fraction;
       })},
      {"confidence_localized_std_xy", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.confidence.localized_std_xy;
       })},
      {"confidence_localized_std_yaw", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.confidence.localized_std_yaw;
       })},
      {"confidence_rival_weight_ratio", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.confidence.rival_weight_ratio;
       })},
      {"confidence_jump_distance", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.confidence.jump_distance;
       })},
      {"confidence_jump_yaw",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.confidence.jump_yaw; })},
      {"confidence_settle_updates",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.confidence.settle_updates; })},
      {"refine_estimate",
       field<bool>([](LocalizerConfig& c) -> bool& { return c.filter.refine_estimate; })},
      {"refine_max_beams",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.refiner.max_beams; })},
      {"refine_max_iterations",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.refiner.max_iterations; })},
      {"refine_outlier_distance", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.refiner.outlier_distance;
       })},
      {"refine_cauchy_scale",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.refiner.cauchy_scale; })},
      {"refine_wall_offset",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.refiner.wall_offset; })},
      {"refine_min_matched_fraction", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.refiner.min_matched_fraction;
       })},
      {"refine_min_matched_beams",
       field<int>([](LocalizerConfig& c) -> int& { return c.filter.refiner.min_matched_beams; })},
      {"refine_max_translation", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.refiner.max_translation;
       })},
      {"refine_max_rotation",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.refiner.max_rotation; })},
      {"refine_beam_std",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.refiner.beam_std; })},
      {"refine_min_beam_std",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.refiner.min_beam_std; })},
      {"refine_degeneracy_ratio", field<double>([](LocalizerConfig& c) -> double& {
         return c.filter.refiner.degeneracy_ratio;
       })},
      {"refine_convergence",
       field<double>([](LocalizerConfig& c) -> double& { return c.filter.refiner.convergence; })},
      {"transform_tolerance",
       field<double>([](LocalizerConfig& c) -> double& { return c.transform_tolerance; })},
      {"tf_publish_rate",
       field<double>([](LocalizerConfig& c) -> double& { return c.tf_publish_rate; })},
      {"gui_publish_rate",
       field<double>([](LocalizerConfig& c) -> double& { return c.gui_publish_rate; })},
      {"cloud_max_poses", field<int>([](LocalizerConfig& c) -> int& { return c.cloud_max_poses; })},
      {"max_update_time",
       field<double>([](LocalizerConfig& c) -> double& { return c.max_update_time; })},
  };
  return params;
}

std::string show(double value) {
  std::ostringstream s;  // shortest form, as the start-up messages
  s << value;
  return s.str();
}

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
  for (const LiveParam& p : liveParams()) names.emplace_back(p.name);
  return names;
}

dynamic_reconfigure::Config liveParamsMessage(const LocalizerConfig& config) {
  LocalizerConfig c = config;  // the accessors give references into a non-const one
  dynamic_reconfigure::Config msg;
  for (const LiveParam& p : liveParams()) {
    if (const auto* f = std::get_if<Field<double>>(&p.field)) {
      msg.doubles.emplace_back();
      msg.doubles.back().name = p.name;
      msg.doubles.back().value = (*f)(c);
    } else if (const auto* i = std::get_if<Field<int>>(&p.field)) {
      msg.ints.emplace_back();
      msg.ints.back().name = p.name;
      msg.ints.back().value = (*i)(c);
    } else {
      msg.bools.emplace_back();
      msg.bools.back().name = p.name;
      msg.bools.back().value = std::get<Field<bool>>(p.field)(c);
    }
  }
  msg.doubles.emplace_back();
  msg.doubles.back().name = "kld_z";
  msg.doubles.back().value = kldZOf(c.filter.kld.confidence);
  msg.bools.emplace_back();
  msg.bools.back().name = "restore_defaults";
  msg.bools.back().value = false;
  return msg;
}

void copyLiveParams(const LocalizerConfig& from, LocalizerConfig* to) {
  LocalizerConfig source = from;
  for (const LiveParam& p : liveParams()) {
    std::visit([&](auto f) { f(*to) = f(source); }, p.field);
  }
}

LiveChange applyLiveParams(const LocalizerConfig& current,
                           const dynamic_reconfigure::Config& request) {
  LiveChange out{current, {}, ""};
  LocalizerConfig& next = out.config;
  for (const LiveParam& p : liveParams()) {
    if (const auto* f = std::get_if<Field<double>>(&p.field)) {
      if (const auto* v = find(request.doubles, p.name)) (*f)(next) = v->value;
    } else if (const auto* i = std::get_if<Field<int>>(&p.field)) {
      if (const auto* v = find(request.ints, p.name)) (*i)(next) = v->value;
    } else if (const auto* v = find(request.bools, p.name)) {
      std::get<Field<bool>>(p.field)(next) = v->value;
    }
  }
  // amcl's kld_z: taken when it moved and kld_confidence did not (a client
  // that only knows amcl's name), as readConfig takes it when ours is absent.
  const auto* z = find(request.doubles, "kld_z");
  const double z_was = kldZOf(current.filter.kld.confidence);
  std::string from_kld_z;
  if (z != nullptr && next.filter.kld.confidence == current.filter.kld.confidence &&
      std::fabs(z->value - z_was) > 1e-9 * std::max(1.0, std::fabs(z_was))) {
    const double p = kldConfidenceFromZ(z->value);
    if (!(std::isfinite(z->value) && p > 0.0 && p < 1.0)) {
      out.error = "invalid parameter kld_z = " + show(z->value) +
                  ": must be a finite normal quantile between -8 and 8";
      return out;
    }
    next.filter.kld.confidence = p;
    from_kld_z = " (amcl's kld_z " + show(z_was) + " -> " + show(z->value) + ")";
  }
  // amcl spells "use the scan's own limit" as -1, as at start-up.
  next.filter.sensor.range_min = std::max(next.filter.sensor.range_min, 0.0);
  next.filter.sensor.range_max = std::max(next.filter.sensor.range_max, 0.0);

  // What changed, as it will be in effect.
  LocalizerConfig before = current, after = next;
  for (const LiveParam& p : liveParams()) {
    std::visit(
        [&](auto f) {
          if (f(after) == f(before)) return;
          out.changed.push_back(std::string(p.name) + " " + show(f(before)) + " -> " +
                                show(f(after)) +
                                (std::string(p.name) == "kld_confidence" ? from_kld_z : ""));
        },
        p.field);
  }
  try {
    validate(next);
  } catch (const std::invalid_argument& e) {
    out.error = e.what();
  }
  return out;
}

}  // namespace pf_ros

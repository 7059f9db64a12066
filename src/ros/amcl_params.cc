#include "pf_localization/ros/amcl_params.h"

#include <cmath>

namespace pf_ros {

const std::vector<std::pair<std::string, std::string>>& amclAliases() {
  // kld_z is an alias with a conversion (kldConfidenceFromZ), applied by readConfig.
  static const std::vector<std::pair<std::string, std::string>> aliases = {
      {"global_frame", "global_frame_id"},
      {"odom_frame", "odom_frame_id"},
      {"base_frame", "base_frame_id"},
      {"kld_confidence", "kld_z"},
  };
  return aliases;
}

std::optional<std::string> amclAliasOf(const std::string& ours) {
  for (const auto& [our_name, amcl_name] : amclAliases()) {
    if (our_name == ours) return amcl_name;
  }
  return std::nullopt;
}

double kldConfidenceFromZ(double kld_z) {
  // Phi(z) = erfc(-z / sqrt(2)) / 2, accurate in both tails (1 + erf would
  // lose the small probabilities of a very negative z to cancellation).
  return 0.5 * std::erfc(-kld_z / std::sqrt(2.0));
}

std::string laserModelTypeError(const std::string& type) {
  if (type == "likelihood_field" || type == "likelihood_field_prob") return "";
  if (type == "beam") {
    return "laser_model_type 'beam' is not available: only the likelihood field model is "
           "implemented (set likelihood_field; laser_z_hit, laser_z_rand and laser_sigma_hit "
           "mean the same there, laser_z_short, laser_z_max and laser_lambda_short have no "
           "counterpart)";
  }
  return "laser_model_type must be likelihood_field (or likelihood_field_prob), got '" + type + "'";
}

const std::vector<AmclOnlyParam>& amclOnlyParams() {
  static const char* const kStdWarnWhy =
      "thresholds of amcl's standard-deviation diagnostic; pf_node's /diagnostics use "
      "confidence_localized_std_xy and confidence_localized_std_yaw instead";
  static const std::vector<AmclOnlyParam> params = {
      {"resample_interval",
       "amcl resamples every N updates; this filter resamples when the effective sample size "
       "falls below resample_ess_fraction of the particles, which keeps particle diversity "
       "without a fixed interval"},
      {"selective_resampling",
       "resampling here is always selective (effective sample size below "
       "resample_ess_fraction x N; amcl's selective_resampling is the same test at 0.5)"},
      {"laser_z_short", "a beam-model weight (only the likelihood field model is implemented)"},
      {"laser_z_max", "a beam-model weight (only the likelihood field model is implemented)"},
      {"laser_lambda_short",
       "a beam-model parameter (only the likelihood field model is implemented)"},
      {"do_beamskip", "beam skipping (amcl's likelihood_field_prob) is not implemented"},
      {"beam_skip_distance", "beam skipping (amcl's likelihood_field_prob) is not implemented"},
      {"beam_skip_threshold", "beam skipping (amcl's likelihood_field_prob) is not implemented"},
      {"beam_skip_error_threshold",
       "beam skipping (amcl's likelihood_field_prob) is not implemented"},
      // amcl reads this misspelling first; configurations written for it exist.
      {"beam_skip_error_threshold_",
       "beam skipping (amcl's likelihood_field_prob) is not implemented"},
      {"std_warn_level_x", kStdWarnWhy},
      {"std_warn_level_y", kStdWarnWhy},
      {"std_warn_level_yaw", kStdWarnWhy},
      {"bag_scan_period", "for amcl --run-from-bag; pf_bag_runner replays a bag instead"},
      {"restore_defaults",
       "a dynamic_reconfigure action, not a setting (pf_node's server offers it: back to the "
       "values the node started with)"},
  };
  return params;
}

}  // namespace pf_ros

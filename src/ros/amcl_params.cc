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
      // amcl reads only this misspelling; configurations written for it exist.
      {"beam_skip_error_threshold", "beam_skip_error_threshold_"},
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
  if (type == "likelihood_field" || type == "likelihood_field_prob" || type == "beam") return "";
  return "laser_model_type must be likelihood_field, likelihood_field_prob or beam, got '" + type +
         "'";
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

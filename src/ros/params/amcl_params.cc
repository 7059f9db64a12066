#include "pf_localization/ros/params/amcl_params.h"

#include <cmath>

namespace pf_ros {

double kldConfidenceFromZ(double kld_z) {
  // Phi(z) = erfc(-z / sqrt(2)) / 2, accurate in both tails (1 + erf would
  // lose the small probabilities of a very negative z to cancellation).
  return 0.5 * std::erfc(-kld_z / std::sqrt(2.0));
}

const std::vector<AmclOnlyParam>& amclOnlyParams() {
  static const char* const kStdWarnWhy =
      "thresholds of amcl's standard-deviation diagnostic; pf_node's /diagnostics judge the "
      "spread of the heaviest cluster themselves (README.md, \"How far to trust it\")";
  static const std::vector<AmclOnlyParam> params = {
      {"resample_interval",
       "amcl resamples every N updates; this filter resamples when the effective sample size "
       "falls below half the particles, which keeps particle diversity without a fixed "
       "interval"},
      {"selective_resampling",
       "resampling here is always selective (effective sample size below half the particles: "
       "amcl's selective_resampling test)"},
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

// What amcl's ROS 1 parameters are here beyond the parameter table (which
// names amcl's spelling of each of ours, ParamInfo::amcl_name): how to convert
// kld_z, and which amcl parameters have no counterpart here (and why).
// README.md, "Switching from amcl", is the user-facing table of all of it.
#pragma once

#include <string>
#include <vector>

namespace pf_ros {

/// amcl's kld_z is the standard normal quantile z that KLD-sampling uses
/// directly; our kld_confidence is the probability p with z = Phi^-1(p).
/// So p = Phi(kld_z), the normal CDF. amcl's default kld_z 0.99 is p = 0.839.
double kldConfidenceFromZ(double kld_z);

/// A parameter amcl reads that has no effect here.
struct AmclOnlyParam {
  const char* name;
  const char* why;  // for the log line "amcl parameter NAME ignored: WHY"
};

/// amcl parameters we accept (no "unknown parameter" warning) without using
/// them: diagnostics', dynamic_reconfigure's, resample_interval,
/// selective_resampling, bag_scan_period.
const std::vector<AmclOnlyParam>& amclOnlyParams();

}  // namespace pf_ros

// amcl's ROS 1 parameter names, so that a configuration written for amcl
// configures pf_localization too. readConfig() asks this file which of our
// parameters amcl spells differently, how to convert kld_z, which laser models
// exist, and which amcl parameters have no counterpart here (and why).
// README.md, "Switching from amcl", is the user-facing table of all of it.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace pf_ros {

/// amcl's name for one of our parameters, when it differs from ours
/// (odom_frame_id for odom_frame, ...). Names that amcl and we share
/// (min_particles, laser_z_hit, ...) are not aliases: they are the same parameter.
std::optional<std::string> amclAliasOf(const std::string& ours);

/// Every (ours, amcl's) pair that amclAliasOf() knows.
const std::vector<std::pair<std::string, std::string>>& amclAliases();

/// amcl's kld_z is the standard normal quantile z that KLD-sampling uses
/// directly; our kld_confidence is the probability p with z = Phi^-1(p).
/// So p = Phi(kld_z), the normal CDF. amcl's default kld_z 0.99 is p = 0.839.
double kldConfidenceFromZ(double kld_z);

/// Empty when `type` names one of amcl's laser models (likelihood_field,
/// likelihood_field_prob: the same with beam skipping when do_beamskip is
/// set, beam); otherwise why it is refused.
std::string laserModelTypeError(const std::string& type);

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

// The filter's confidence as a diagnostic_msgs/DiagnosticStatus: what pf_node
// publishes on /diagnostics and pf_status after every update.
#pragma once

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <string>

#include "pf_localization/core/particle_filter.h"

namespace pf_ros {

/// OK when localized, WARN when uncertain, ERROR when lost; the message is the
/// state and its reason, the values every figure behind it.
diagnostic_msgs::DiagnosticStatus toDiagnosticStatus(const pf::ParticleFilter& filter,
                                                     const pf::UpdateReport& report,
                                                     const std::string& name);

}  // namespace pf_ros

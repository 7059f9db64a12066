// The files a user reads about the parameters, written from the one table
// (localizerParameters()): config/pf.yaml, cfg/PfLocalization.cfg, the
// manual's table (docs/parameters.md) and `pf_node --help`. scripts/generate_param_files.sh writes
// the committed files with pf_param_docs; a unit test fails when one of them
// differs from what the table says, so they cannot drift.
#pragma once

#include <string>

namespace pf_ros {

/// config/pf.yaml: every parameter at its default, grouped, one comment each
/// with unit, range and description; a parameter whose default is "unset"
/// (initial_pose_x) is shown commented out.
std::string configYaml();

/// cfg/PfLocalization.cfg: the live parameters for dynamic_reconfigure, with
/// their sliders, plus amcl's kld_z and restore_defaults.
std::string reconfigureCfg();

/// The manual's table (docs/parameters.md): name, default, unit, range, live, amcl, description.
std::string parameterMarkdown();

/// `pf_node --help`: usage, then one line per parameter.
std::string parameterHelp(const std::string& program);

/// When the command line asks for -h or --help (before any ROS remapping is
/// read, so no master is needed): prints parameterHelp on stdout and returns true.
bool printHelpIfAsked(int argc, char** argv, const std::string& program);

}  // namespace pf_ros

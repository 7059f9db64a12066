// pf_param_docs: prints a file generated from the parameter table
// (ros/parameter_docs.h), for scripts/generate_param_files.sh.
#include <iostream>
#include <string>

#include "pf_localization/ros/params/parameter_docs.h"

int main(int argc, char** argv) {
  const std::string what = argc == 2 ? argv[1] : "";
  if (what == "yaml") {
    std::cout << pf_ros::configYaml();
  } else if (what == "cfg") {
    std::cout << pf_ros::reconfigureCfg();
  } else if (what == "markdown") {
    std::cout << pf_ros::parameterMarkdown();
  } else if (what == "help") {
    std::cout << pf_ros::parameterHelp("pf_node");
  } else {
    std::ostream& out = what == "-h" || what == "--help" ? std::cout : std::cerr;
    out << "usage: pf_param_docs yaml|cfg|markdown|help\n"
           "  prints config/pf.yaml, cfg/PfLocalization.cfg, the README's parameter table or\n"
           "  pf_node --help, as the parameter table says they are\n";
    return &out == &std::cout ? 0 : 2;
  }
  return 0;
}

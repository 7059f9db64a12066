#include "pf_localization/ros/params/parameter_docs.h"

#include <cmath>
#include <iostream>
#include <sstream>
#include <variant>
#include <vector>

#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {
namespace {

using Row = pf::Parameter<LocalizerConfig>;

// The groups in the order of the table, each with its title.
struct Group {
  std::string name;
  std::string title;
};

const std::vector<Group>& groups() {
  static const std::vector<Group> g = {
      {"frames", "Frames"},
      {"output", "Output and maps"},
      {"initial_pose", "Initial pose (leave initial_pose_x unset for global localization)"},
      {"particles", "Particles (KLD-sampling)"},
      {"updates", "When the filter updates"},
      {"recovery", "Recovery (augmented MCL)"},
      {"motion", "Motion model"},
      {"sensor", "Sensor model"},
      {"refinement", "Refinement: the published pose fitted to the map"},
      {"compute", "Computing: threads"},
      {"scan", "Scans"},
  };
  return g;
}

// A default as YAML and Python read it back: doubles keep a decimal point.
std::string literal(double v) {
  std::string s = pf::formatNumber(v);
  if (s.find_first_of(".eni") == std::string::npos) s += ".0";
  return s;
}
std::string literal(int v) { return std::to_string(v); }
std::string literal(bool v) { return v ? "true" : "false"; }
// An empty text as YAML reads it (a bare "name:" would be null).
std::string literal(const std::string& v) { return v.empty() ? "\"\"" : v; }

std::string defaultText(const Row& p) {
  const LocalizerConfig defaults;
  return std::visit([&](const auto& f) { return literal(f.get(defaults)); }, p.field);
}

bool unsetByDefault(const Row& p) {
  const LocalizerConfig defaults;
  const auto* f = std::get_if<pf::Field<LocalizerConfig, double>>(&p.field);
  return f != nullptr && std::isnan(f->get(defaults));
}

// What the value may be, for a comment: "m, > 0" or "first_beam or last_beam".
std::string rangeText(const Row& p) {
  if (std::holds_alternative<pf::Field<LocalizerConfig, bool>>(p.field)) return "true or false";
  if (std::holds_alternative<pf::Field<LocalizerConfig, std::string>>(p.field) &&
      p.info.choices.empty()) {
    return p.info.unit.empty() ? "a frame name" : p.info.unit;
  }
  return pf::allowedText(p.info);
}

std::string amclText(const pf::ParamInfo& info) {
  switch (info.amcl_kind) {
    case pf::Amcl::kSameName:
      return "amcl";
    case pf::Amcl::kAlias:
      return "amcl: " + info.amcl_name;
    case pf::Amcl::kOursOnly:
      break;
  }
  return "ours";
}

// A Python string literal.
std::string py(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'' || c == '\\') out += '\\';
    out += c;
  }
  return out + "'";
}

const char* kYamlHeader =
    "# pf_localization parameters: every parameter of pf_node and pf_bag_runner, at its\n"
    "# default. GENERATED from the parameter table (ros/params/localizer_config.cc and the core's\n"
    "# options) by scripts/generate_param_files.sh; a unit test checks that it matches.\n"
    "# Loaded into pf_node's private namespace by launch/localization.launch and read by\n"
    "# `pf_bag_runner --params`. Each comment: [unit] valid values (live: can change while\n"
    "# pf_node runs; amcl: amcl's parameter too) description. docs/parameters.md.\n";

}  // namespace

std::string configYaml() {
  std::ostringstream out;
  out << kYamlHeader;
  for (const Group& g : groups()) {
    out << "\n# --- " << g.title << " ---\n";
    for (const Row& p : localizerParameters()) {
      if (p.info.group != g.name) continue;
      std::string line =
          (unsetByDefault(p) ? "# " + p.info.name + ": 0.0" : p.info.name + ": " + defaultText(p));
      if (line.size() < 34) line.resize(34, ' ');
      out << line << " # " << rangeText(p) << (p.info.is_live ? "; live" : "")
          << (p.info.amcl_kind != pf::Amcl::kOursOnly ? "; " + amclText(p.info) : "") << ". "
          << p.info.description << "\n";
    }
  }
  return out.str();
}

std::string reconfigureCfg() {
  std::ostringstream out;
  out << "#!/usr/bin/env python3\n"
         "# pf_node's live parameters (dynamic_reconfigure). GENERATED from the parameter table\n"
         "# by scripts/generate_param_files.sh; a unit test checks that it matches. pf_node\n"
         "# starts the server from the values it read at start-up, and checks every request\n"
         "# as at start-up (\"invalid parameter NAME = V: must be RANGE\"). kld_z is amcl's name\n"
         "# for kld_confidence (a normal quantile); restore_defaults is amcl's action.\n"
         "from dynamic_reconfigure.parameter_generator_catkin import ParameterGenerator, "
         "double_t, int_t, bool_t, str_t\n\n"
         "PACKAGE = 'pf_localization'\n\ngen = ParameterGenerator()\n";
  int level = 0;
  for (const Group& g : groups()) {
    bool opened = false;
    for (const Row& p : localizerParameters()) {
      if (p.info.group != g.name || !p.info.is_live) continue;
      if (!opened) out << "\n" << g.name << " = gen.add_group(" << py(g.name) << ")\n";
      opened = true;
      const std::string description =
          "[" + (p.info.unit.empty() ? std::string("-") : p.info.unit) + "] " + p.info.description;
      const std::string head = g.name + ".add(" + py(p.info.name) + ", ";
      std::visit(
          [&](const auto& f) {
            using T = std::decay_t<decltype(f.get(LocalizerConfig()))>;
            const char* type = std::is_same_v<T, double> ? "double_t"
                               : std::is_same_v<T, int>  ? "int_t"
                               : std::is_same_v<T, bool> ? "bool_t"
                                                         : "str_t";
            out << head << type << ", " << (1 << level) << ", " << py(description) << ", ";
            if constexpr (std::is_same_v<T, bool>) {
              out << (f.get(LocalizerConfig()) ? "True" : "False") << ")\n";
            } else if constexpr (std::is_same_v<T, std::string>) {
              out << py(f.get(LocalizerConfig())) << ")\n";
            } else if constexpr (std::is_same_v<T, int>) {
              out << f.get(LocalizerConfig()) << ", " << static_cast<long>(p.info.slider_min)
                  << ", " << static_cast<long>(p.info.slider_max) << ")\n";
            } else {
              out << literal(f.get(LocalizerConfig())) << ", " << literal(p.info.slider_min) << ", "
                  << literal(p.info.slider_max) << ")\n";
            }
          },
          p.field);
      if (p.info.name == "kld_confidence") {
        out << g.name << ".add('kld_z', double_t, " << (1 << level)
            << ", \"[-] amcl's name: kld_confidence as a normal quantile\", "
            << literal(pf::normalQuantile(LocalizerConfig().filter.kld.confidence))
            << ", -8.0, 8.0)\n";
      }
    }
    if (opened) ++level;
  }
  out << "\n# amcl's action: back to the values pf_node started with (then false again).\n"
         "gen.add('restore_defaults', bool_t, 0xff, 'restore the values pf_node started with', "
         "False)\n\nexit(gen.generate(PACKAGE, 'pf_node', 'PfLocalization'))\n";
  return out.str();
}

std::string parameterMarkdown() {
  std::ostringstream out;
  out << "| parameter | default | values | live | amcl | what it does |\n"
         "|---|---|---|---|---|---|\n";
  for (const Row& p : localizerParameters()) {
    out << "| `" << p.info.name << "` | " << (unsetByDefault(p) ? "unset" : defaultText(p)) << " | "
        << rangeText(p) << " | " << (p.info.is_live ? "yes" : "no") << " | "
        << (p.info.amcl_kind == pf::Amcl::kAlias      ? "`" + p.info.amcl_name + "`"
            : p.info.amcl_kind == pf::Amcl::kSameName ? std::string("yes")
                                                      : std::string("ours"))
        << " | " << p.info.description << " |\n";
  }
  return out.str();
}

std::string parameterHelp(const std::string& program) {
  std::ostringstream out;
  out << "usage: " << program << " [__name:=NAME] [_PARAM:=VALUE ...]\n"
      << "  (rosrun pf_localization pf_node, or roslaunch pf_localization localization.launch)\n\n"
      << "Subscribes scan, odom, map, initialpose; publishes map -> odom on tf, pf_pose, "
         "amcl_pose,\nparticlecloud, pf_hypotheses, pf_status, pf_map_changes and /diagnostics. "
         "Parameters "
         "(private namespace;\namcl's names are accepted too), with default and valid values; "
         "live ones can change\nwhile it runs (dynamic_reconfigure):\n";
  for (const Row& p : localizerParameters()) {
    out << "  " << p.info.name << " = " << (unsetByDefault(p) ? "unset" : defaultText(p)) << "  ("
        << rangeText(p) << (p.info.is_live ? "; live" : "")
        << (p.info.amcl_kind == pf::Amcl::kAlias ? "; amcl: " + p.info.amcl_name : "") << ")\n"
        << "      " << p.info.description << "\n";
  }
  return out.str();
}

bool printHelpIfAsked(int argc, char** argv, const std::string& program) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << parameterHelp(program);
      return true;
    }
  }
  return false;
}

}  // namespace pf_ros

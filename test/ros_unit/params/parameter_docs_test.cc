// The parameter table is the one declaration of every parameter: the files
// generated from it are what it says (scripts/generate_param_files.sh), each
// name is declared once, its default is valid and reads back from
// config/pf.yaml, and a value out of its range is refused by name.
#include "pf_localization/ros/params/parameter_docs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <variant>

#include "pf_localization/core/util/parameter_table.h"
#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {
namespace {

std::string readFile(const std::string& relative) {
  std::ifstream in(std::string(PF_SOURCE_DIR) + "/" + relative);
  EXPECT_TRUE(in.good()) << relative;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::unique_ptr<ParamSource> yamlText(const std::string& text) {
  const std::string path = testing::TempDir() + "parameter_docs_test.yaml";
  std::ofstream(path) << text;
  return yamlParamSource(path);
}

constexpr const char* kRegenerate = "; run scripts/generate_param_files.sh";

TEST(ParameterDocs, ConfigPfYamlIsTheTables) {
  EXPECT_EQ(configYaml(), readFile("config/pf.yaml")) << "config/pf.yaml is stale" << kRegenerate;
}

TEST(ParameterDocs, TheReconfigureCfgIsTheTables) {
  EXPECT_EQ(reconfigureCfg(), readFile("cfg/PfLocalization.cfg"))
      << "cfg/PfLocalization.cfg is stale" << kRegenerate;
}

TEST(ParameterDocs, TheManualsTableIsTheTables) {
  const std::string page = readFile("docs/parameters.md");
  const std::string begin = "<!-- parameters:begin -->\n", end = "<!-- parameters:end -->";
  const auto b = page.find(begin), e = page.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  EXPECT_EQ(parameterMarkdown(), page.substr(b + begin.size(), e - b - begin.size()))
      << "docs/parameters.md's parameter table is stale" << kRegenerate;
}

// The public surface is kept small: what an amcl user knows and what a
// robot or a building needs (51, its floors file among them), and the
// sensors' own: the scan topics, and for point clouds their topics and
// height band, and where the map's changes are saved (map_changes_file).
constexpr std::size_t kMaxParameters = 57;

TEST(ParameterDocs, EachNameIsDeclaredOnceAndThereAreAtMostFiftySeven) {
  std::set<std::string> names;
  for (const auto& p : localizerParameters()) {
    EXPECT_TRUE(names.insert(p.info.name).second) << p.info.name << " declared twice";
    if (p.info.amcl_kind == pf::Amcl::kAlias) {
      EXPECT_TRUE(names.insert(p.info.amcl_name).second) << p.info.amcl_name;
    }
    EXPECT_FALSE(p.info.group.empty()) << p.info.name << " is in no group";
    EXPECT_FALSE(p.info.description.empty()) << p.info.name;
  }
  EXPECT_LE(localizerParameters().size(), kMaxParameters);
}

TEST(ParameterDocs, EveryDefaultIsValidAndReadsBackFromPfYaml) {
  EXPECT_NO_THROW(validate(LocalizerConfig()));
  ConfigNotes notes;
  const LocalizerConfig read = readConfig(*yamlText(readFile("config/pf.yaml")), nullptr, &notes);
  EXPECT_TRUE(notes.warnings.empty()) << notes.warnings[0];
  const LocalizerConfig defaults;
  for (const auto& p : localizerParameters()) {
    std::visit(
        [&](const auto& f) {
          const auto a = f.get(read), b = f.get(defaults);
          if constexpr (std::is_same_v<std::decay_t<decltype(a)>, double>) {
            if (std::isnan(b)) {
              EXPECT_TRUE(std::isnan(a)) << p.info.name;
              return;
            }
          }
          EXPECT_EQ(a, b) << p.info.name;
        },
        p.field);
  }
}

// Just outside a number's range, or a word not in a string's vocabulary.
std::optional<std::string> outside(const pf::ParamInfo& info, bool integer) {
  const pf::Range& r = info.range;
  if (!info.choices.empty()) return std::string("no_such_choice");
  if (std::isfinite(r.min)) {
    const double v = r.min_open ? r.min : r.min - (integer ? 1.0 : 0.5);
    return integer ? std::to_string(static_cast<int>(v)) : pf::formatNumber(v);
  }
  if (std::isfinite(r.max)) {
    const double v = r.max_open ? r.max : r.max + (integer ? 1.0 : 0.5);
    return integer ? std::to_string(static_cast<int>(v)) : pf::formatNumber(v);
  }
  return std::nullopt;
}

TEST(ParameterDocs, AValueOutsideItsRangeIsRefusedByName) {
  int checked = 0;
  for (const auto& p : localizerParameters()) {
    const bool integer = std::holds_alternative<pf::Field<LocalizerConfig, int>>(p.field);
    if (std::holds_alternative<pf::Field<LocalizerConfig, bool>>(p.field)) continue;
    // Negative range limits mean the scan's own, as in amcl.
    if (p.info.name == "laser_min_range" || p.info.name == "laser_max_range") continue;
    const std::optional<std::string> bad = outside(p.info, integer);
    if (!bad) continue;
    ConfigNotes notes;
    try {
      // (beam_skip_* are checked while do_beamskip is on, as they are used only then.)
      readConfig(*yamlText("do_beamskip: true\n" + p.info.name + ": " + *bad + "\n"), nullptr,
                 &notes);
      ADD_FAILURE() << p.info.name << " = " << *bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(0u, std::string(e.what()).find("invalid parameter " + p.info.name + " = "))
          << e.what();
      EXPECT_NE(std::string::npos, std::string(e.what()).find(pf::allowedText(p.info))) << e.what();
    }
    ++checked;
  }
  EXPECT_GE(checked, 30);
}

TEST(ParameterDocs, ANegativeParticleCountSaysItMustBePositive) {
  ConfigNotes notes;
  try {
    readConfig(*yamlText("max_particles: -5\n"), nullptr, &notes);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string("invalid parameter max_particles = -5: must be >= 1 (particles)"),
              e.what());
  }
}

TEST(ParameterDocs, AWrongTypeSaysWhatWasExpected) {
  ConfigNotes notes;
  try {
    readConfig(*yamlText("max_particles: many\n"), nullptr, &notes);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("expected an integer, got 'many'"))
        << e.what();
  }
}

TEST(ParameterDocs, HelpListsEveryParameterWithDefaultAndRange) {
  const std::string help = parameterHelp("pf_node");
  for (const auto& p : localizerParameters()) {
    EXPECT_NE(std::string::npos, help.find("  " + p.info.name + " = ")) << p.info.name;
  }
  EXPECT_NE(std::string::npos, help.find("laser_sigma_hit = 0.2  (> 0 (m); live)")) << help;
}

}  // namespace
}  // namespace pf_ros

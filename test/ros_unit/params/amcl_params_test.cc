// readConfig with amcl's parameter names: aliases, precedence, kld_z, the
// laser model, amcl-only parameters and unknown names.
#include "pf_localization/ros/params/amcl_params.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {
namespace {

// A YAML ParamSource over `text` (the file is removed at once: the source
// holds the parsed document).
std::unique_ptr<ParamSource> yaml(const std::string& text) {
  char path[] = "/tmp/amcl_params_test_XXXXXX";
  const int fd = mkstemp(path);
  EXPECT_GE(fd, 0);
  close(fd);
  std::ofstream(path) << text;
  auto source = yamlParamSource(path);
  std::remove(path);
  return source;
}

bool anyContains(const std::vector<std::string>& lines, const std::string& what) {
  for (const std::string& line : lines) {
    if (line.find(what) != std::string::npos) return true;
  }
  return false;
}

TEST(AmclParams, FrameAliasesSetOurFrames) {
  ConfigNotes notes;
  const LocalizerConfig c = readConfig(
      *yaml(
          "odom_frame_id: odom_combined\nbase_frame_id: base_footprint\nglobal_frame_id: world\n"),
      nullptr, &notes);
  EXPECT_EQ(c.odom_frame, "odom_combined");
  EXPECT_EQ(c.base_frame, "base_footprint");
  EXPECT_EQ(c.global_frame, "world");
  EXPECT_TRUE(notes.warnings.empty());
}

TEST(AmclParams, LeadingSlashOfTfEraFramesIsDropped) {
  ConfigNotes notes;
  const LocalizerConfig c =
      readConfig(*yaml("odom_frame_id: /odom\nbase_frame: /base_link\n"), nullptr, &notes);
  EXPECT_EQ(c.odom_frame, "odom");
  EXPECT_EQ(c.base_frame, "base_link");
}

TEST(AmclParams, BothNamesMeaningTheSameAreNoConflict) {
  // As pf_node's dynamic_reconfigure server leaves them for a respawned node.
  ConfigNotes notes;
  const LocalizerConfig c =
      readConfig(*yaml("kld_confidence: 0.99\nkld_z: 2.3263478740408408\nodom_frame: odom\n"
                       "odom_frame_id: odom\n"),
                 nullptr, &notes);
  EXPECT_EQ(c.filter.kld.confidence, 0.99);
  EXPECT_TRUE(notes.warnings.empty()) << notes.warnings[0];
}

TEST(AmclParams, OurNameWinsOverAmclsInTheSameSourceWithAWarning) {
  ConfigNotes notes;
  const LocalizerConfig c =
      readConfig(*yaml("odom_frame: odom\nodom_frame_id: wheel_odom\n"), nullptr, &notes);
  EXPECT_EQ(c.odom_frame, "odom");
  ASSERT_EQ(notes.warnings.size(), 1u);
  EXPECT_NE(notes.warnings[0].find("odom_frame_id"), std::string::npos) << notes.warnings[0];
  EXPECT_NE(notes.warnings[0].find("using odom_frame"), std::string::npos) << notes.warnings[0];
}

TEST(AmclParams, AmclNameInTheSourceBeatsOurNameInTheDefaults) {
  // amcl_compatible.launch: config/pf.yaml as defaults under an amcl configuration.
  const auto defaults = yaml("odom_frame: odom\nkld_confidence: 0.99\nmax_particles: 50000\n");
  ConfigNotes notes;
  const LocalizerConfig c =
      readConfig(*yaml("odom_frame_id: wheel_odom\nkld_z: 0.99\n"), defaults.get(), &notes);
  EXPECT_EQ(c.odom_frame, "wheel_odom");
  EXPECT_NEAR(c.filter.kld.confidence, kldConfidenceFromZ(0.99), 1e-12);
  EXPECT_EQ(c.filter.kld.max_particles, 50000);  // from the defaults
  EXPECT_TRUE(notes.warnings.empty());
}

TEST(AmclParams, KldZIsTheNormalQuantileOfOurConfidence) {
  EXPECT_NEAR(kldConfidenceFromZ(0.0), 0.5, 1e-15);
  EXPECT_NEAR(kldConfidenceFromZ(0.99), 0.83891294, 1e-8);  // amcl's default
  EXPECT_NEAR(kldConfidenceFromZ(1.6448536269514722), 0.95, 1e-12);
  EXPECT_NEAR(kldConfidenceFromZ(2.3263478740408408), 0.99, 1e-12);
  EXPECT_NEAR(kldConfidenceFromZ(-2.3263478740408408), 0.01, 1e-12);

  ConfigNotes notes;
  EXPECT_NEAR(
      readConfig(*yaml("kld_z: 2.3263478740408408\n"), nullptr, &notes).filter.kld.confidence, 0.99,
      1e-12);
  EXPECT_THROW(readConfig(*yaml("kld_z: 40.0\n"), nullptr, &notes), std::invalid_argument);
  EXPECT_THROW(readConfig(*yaml("kld_z: .nan\n"), nullptr, &notes), std::invalid_argument);
}

TEST(AmclParams, EveryAmclLaserModelIsAccepted) {
  ConfigNotes notes;
  EXPECT_EQ(readConfig(*yaml("laser_model_type: likelihood_field\n"), nullptr, &notes)
                .filter.laser_model_type,
            pf::LaserModelType::kLikelihoodField);
  EXPECT_EQ(readConfig(*yaml("laser_model_type: likelihood_field_prob\n"), nullptr, &notes)
                .filter.laser_model_type,
            pf::LaserModelType::kLikelihoodFieldProb);
  EXPECT_EQ(readConfig(*yaml("laser_model_type: beam\n"), nullptr, &notes).filter.laser_model_type,
            pf::LaserModelType::kBeam);
  try {
    readConfig(*yaml("laser_model_type: lidar\n"), nullptr, &notes);
    FAIL() << "an unknown model was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("likelihood_field, likelihood_field_prob or beam"),
              std::string::npos)
        << e.what();
  }
}

TEST(AmclParams, BeamModelAndBeamSkipParametersAreRead) {
  ConfigNotes notes;
  const LocalizerConfig c = readConfig(*yaml("laser_model_type: likelihood_field_prob\n"
                                             "laser_z_short: 0.2\nlaser_z_max: 0.01\n"
                                             "laser_lambda_short: 0.3\ndo_beamskip: true\n"
                                             "beam_skip_distance: 0.4\nbeam_skip_threshold: 0.2\n"
                                             "beam_skip_error_threshold_: 0.8\n"),
                                       nullptr, &notes);
  EXPECT_TRUE(notes.warnings.empty());
  EXPECT_EQ(c.filter.beam.z_short, 0.2);
  EXPECT_EQ(c.filter.beam.z_max, 0.01);
  EXPECT_EQ(c.filter.beam.lambda_short, 0.3);
  EXPECT_TRUE(c.filter.sensor.beam_skip);
  EXPECT_EQ(c.filter.sensor.beam_skip_distance, 0.4);
  EXPECT_EQ(c.filter.sensor.beam_skip_threshold, 0.2);
  // amcl's misspelling is read as the right name.
  EXPECT_EQ(c.filter.sensor.beam_skip_error_threshold, 0.8);
  // Under another model, as in amcl, do_beamskip does nothing, and says so.
  ConfigNotes plain_notes;
  readConfig(*yaml("do_beamskip: true\n"), nullptr, &plain_notes);
  EXPECT_TRUE(anyContains(plain_notes.infos, "beam skipping is part of likelihood_field_prob"));
  EXPECT_FALSE(anyContains(notes.infos, "beam skipping is part of likelihood_field_prob"));
  EXPECT_THROW(readConfig(*yaml("do_beamskip: true\nbeam_skip_threshold: 1.5\n"), nullptr, &notes),
               std::invalid_argument);
  EXPECT_THROW(
      readConfig(*yaml("laser_model_type: beam\nlaser_lambda_short: 0\n"), nullptr, &notes),
      std::invalid_argument);
}

TEST(AmclParams, ResampleIntervalIsAcceptedAndExplained) {
  ConfigNotes notes;
  readConfig(*yaml("resample_interval: 1\n"), nullptr, &notes);
  EXPECT_TRUE(notes.warnings.empty());
  EXPECT_TRUE(anyContains(notes.infos, "resample_interval ignored"));
  EXPECT_TRUE(anyContains(notes.infos, "effective sample size"));
}

TEST(AmclParams, NodeParameters) {
  ConfigNotes notes;
  LocalizerConfig c =
      readConfig(*yaml("gui_publish_rate: 10.0\nsave_pose_rate: 2.0\n"), nullptr, &notes);
  EXPECT_EQ(c.gui_publish_rate, 10.0);
  EXPECT_EQ(c.save_pose_rate, 2.0);
  EXPECT_FALSE(c.first_map_only);

  c = readConfig(*yaml("first_map_only: true\n"), nullptr, &notes);
  EXPECT_TRUE(c.first_map_only);
  // amcl's use_map_topic false: one map from static_map, never updated.
  c = readConfig(*yaml("use_map_topic: false\n"), nullptr, &notes);
  EXPECT_TRUE(c.first_map_only);
  c = readConfig(*yaml("use_map_topic: true\n"), nullptr, &notes);
  EXPECT_FALSE(c.first_map_only);
}

TEST(AmclParams, UnknownNamesAreListedInOneWarning) {
  ConfigNotes notes;
  readConfig(*yaml("min_particle: 100\nodom_alpha_1: 0.3\nmax_particles: 2000\n"), nullptr, &notes);
  ASSERT_EQ(notes.warnings.size(), 1u);
  EXPECT_NE(notes.warnings[0].find("min_particle, odom_alpha_1"), std::string::npos)
      << notes.warnings[0];
  EXPECT_EQ(notes.warnings[0].find("max_particles"), std::string::npos) << notes.warnings[0];
}

// Settings that were parameters before they became constants of the filter:
// a configuration that still sets one is told so, not warned of a
// misspelling, and the constant stands.
TEST(AmclParams, RetiredParametersAreNamedAndLeftAlone) {
  ConfigNotes notes;
  const LocalizerConfig c =
      readConfig(*yaml("refine_estimate: true\nrefine_max_beams: 90\nrecovery_patience: 3\n"),
                 nullptr, &notes);
  EXPECT_TRUE(c.filter.refine_estimate);
  EXPECT_EQ(LocalizerConfig().filter.refiner.max_beams, c.filter.refiner.max_beams);
  EXPECT_EQ(LocalizerConfig().filter.recovery.patience, c.filter.recovery.patience);
  EXPECT_TRUE(notes.warnings.empty()) << notes.warnings[0];
  EXPECT_TRUE(anyContains(notes.infos, "refine_max_beams, recovery_patience"));
  EXPECT_TRUE(anyContains(notes.infos, "no longer parameters"));
}

// sensor_threads became threads: the old name is answered with
// the new one, not as a misspelling.
TEST(AmclParams, ARenamedParameterNamesItsNewName) {
  ConfigNotes notes;
  readConfig(*yaml("sensor_threads: 2\n"), nullptr, &notes);
  ASSERT_EQ(1u, notes.warnings.size());
  EXPECT_NE(std::string::npos, notes.warnings[0].find("sensor_threads is now threads"))
      << notes.warnings[0];
  EXPECT_EQ(std::string::npos, notes.warnings[0].find("unknown")) << notes.warnings[0];
}

// max_update_time: read, and refused with the start-up message.
TEST(AmclParams, MaxUpdateTimeIsReadAndValidated) {
  ConfigNotes notes;
  LocalizerConfig c = readConfig(*yaml("max_update_time: 0.02\n"), nullptr, &notes);
  EXPECT_EQ(c.max_update_time, 0.02);
  EXPECT_TRUE(notes.warnings.empty());
  const std::pair<const char*, const char*> bad[] = {
      {"max_update_time: .nan\n",
       "invalid parameter max_update_time = nan: must be <= 10 (s; <= 0: no cap)"},
      {"max_update_time: 60\n",
       "invalid parameter max_update_time = 60: must be <= 10 (s; <= 0: no cap)"}};
  for (const auto& [text, message] : bad) {
    try {
      readConfig(*yaml(text), nullptr, &notes);
      ADD_FAILURE() << text << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(message), e.what());
    }
  }
}

// config/pf.yaml, the defaults under every launch file: all of it known.
TEST(AmclParams, PfYamlHasNoUnknownParameter) {
  const std::string pf_yaml = PF_SOURCE_DIR "/config/pf.yaml";
  ConfigNotes notes;
  readConfig(*yamlParamSource(pf_yaml), nullptr, &notes);
  EXPECT_TRUE(notes.warnings.empty()) << notes.warnings[0];
  EXPECT_TRUE(notes.infos.empty()) << notes.infos[0];
}

// Every parameter amcl (Noetic) reads, at amcl's own default: all accepted,
// none unknown.
TEST(AmclParams, AmclsWholeConfigurationIsAccepted) {
  const char* amcl_defaults = R"(
use_map_topic: false
first_map_only: false
gui_publish_rate: -1.0
save_pose_rate: 0.5
laser_min_range: -1.0
laser_max_range: -1.0
laser_max_beams: 30
min_particles: 100
max_particles: 5000
kld_err: 0.01
kld_z: 0.99
odom_alpha1: 0.2
odom_alpha2: 0.2
odom_alpha3: 0.2
odom_alpha4: 0.2
odom_alpha5: 0.2
do_beamskip: false
beam_skip_distance: 0.5
beam_skip_threshold: 0.3
beam_skip_error_threshold: 0.9
laser_z_hit: 0.95
laser_z_short: 0.1
laser_z_max: 0.05
laser_z_rand: 0.05
laser_sigma_hit: 0.2
laser_lambda_short: 0.1
laser_likelihood_max_dist: 2.0
laser_model_type: likelihood_field
odom_model_type: diff-corrected
update_min_d: 0.2
update_min_a: 0.5235987755982988
odom_frame_id: odom
base_frame_id: base_link
global_frame_id: map
resample_interval: 2
selective_resampling: false
transform_tolerance: 0.1
recovery_alpha_slow: 0.001
recovery_alpha_fast: 0.1
tf_broadcast: true
std_warn_level_x: 0.2
std_warn_level_y: 0.2
std_warn_level_yaw: 0.1
bag_scan_period: -1.0
initial_pose_x: 0.0
initial_pose_y: 0.0
initial_pose_a: 0.0
initial_cov_xx: 0.25
initial_cov_yy: 0.25
initial_cov_aa: 0.06853891945200942
restore_defaults: false
)";
  ConfigNotes notes;
  const LocalizerConfig c = readConfig(*yaml(amcl_defaults), nullptr, &notes);
  EXPECT_TRUE(notes.warnings.empty()) << notes.warnings[0];
  EXPECT_EQ(c.filter.kld.min_particles, 100);
  EXPECT_EQ(c.filter.kld.max_particles, 5000);
  EXPECT_EQ(c.filter.sensor.max_beams, 30);
  EXPECT_EQ(c.filter.sensor.range_min, 0.0);
  EXPECT_EQ(c.filter.recovery.alpha_slow, 0.001);
  ASSERT_TRUE(c.initial_pose.has_value());
  EXPECT_EQ(c.initial_pose->x, 0.0);
  // Each amcl-only parameter gets one line saying why it is ignored.
  for (const AmclOnlyParam& p : amclOnlyParams()) {
    if (std::string(p.name) == "beam_skip_error_threshold_") continue;  // not in the file
    EXPECT_TRUE(anyContains(notes.infos, std::string(p.name) + " ignored")) << p.name;
  }
}

TEST(AmclParams, ScanTopicsAndTheirWeights) {
  ConfigNotes notes;
  const LocalizerConfig c = readConfig(
      *yaml("scan_topics: \"scan_front, scan_rear scan_top\"\nscan_weights: \"1 0.5\"\n"), nullptr,
      &notes);
  EXPECT_EQ((std::vector<std::string>{"scan_front", "scan_rear", "scan_top"}), scanTopics(c));
  // The last weight goes on for the topics after it.
  EXPECT_EQ((std::vector<double>{1.0, 0.5, 0.5}), scanWeights(c));
  // YAML lists, as a ROS user writes them.
  const LocalizerConfig listed = readConfig(
      *yaml("scan_topics: [scan_front, scan_rear]\nscan_weights: [1, 0.5]\n"), nullptr, &notes);
  EXPECT_EQ((std::vector<std::string>{"scan_front", "scan_rear"}), scanTopics(listed));
  EXPECT_EQ((std::vector<double>{1.0, 0.5}), scanWeights(listed));
  // amcl's single scan, and a weight that does not count.
  EXPECT_EQ((std::vector<std::string>{"scan"}), scanTopics(LocalizerConfig()));
  EXPECT_EQ((std::vector<double>{1.0}), scanWeights(LocalizerConfig()));
  for (const char* bad : {"scan_weights: \"1 0\"\n", "scan_weights: \"1 x\"\n",
                          "scan_weights: \"1.5\"\n", "scan_topics: \" , \"\n"}) {
    try {
      readConfig(*yaml(bad), nullptr, &notes);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      const std::string name = std::string(bad).substr(0, std::string(bad).find(':'));
      EXPECT_NE(std::string::npos, what.find("invalid parameter " + name + " = ")) << what;
    }
  }
}

TEST(AmclParams, CloudTopicsAreSensorsAfterTheScanTopics) {
  ConfigNotes notes;
  const LocalizerConfig both = readConfig(
      *yaml("scan_topics: scan_front\ncloud_topics: \"points depth\"\nscan_weights: \"1 0.5\"\n"),
      nullptr, &notes);
  EXPECT_EQ((std::vector<std::string>{"points", "depth"}), cloudTopics(both));
  EXPECT_EQ((std::vector<std::string>{"scan_front", "points", "depth"}), sensorTopics(both));
  EXPECT_EQ((std::vector<double>{1.0, 0.5, 0.5}), scanWeights(both));
  // None by default; clouds alone once scan_topics is empty.
  EXPECT_TRUE(cloudTopics(LocalizerConfig()).empty());
  const LocalizerConfig clouds =
      readConfig(*yaml("scan_topics: \"\"\ncloud_topics: points\n"), nullptr, &notes);
  EXPECT_EQ((std::vector<std::string>{"points"}), sensorTopics(clouds));
  // No sensor at all is refused, naming the parameter.
  try {
    readConfig(*yaml("scan_topics: \"\"\n"), nullptr, &notes);
    ADD_FAILURE() << "accepted a configuration without a sensor";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string::npos, std::string(e.what()).find("invalid parameter scan_topics = "))
        << e.what();
  }
}

}  // namespace
}  // namespace pf_ros

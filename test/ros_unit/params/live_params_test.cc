// The live parameters (dynamic_reconfigure): the .cfg and the table agree,
// the .cfg's defaults are config/pf.yaml's, requests are checked as at
// start-up, and the filter keeps its particles through a change.
#include "pf_localization/ros/params/live_params.h"

#include <gtest/gtest.h>
#include <pf_localization/PfLocalizationConfig.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "pf_localization/ros/localizer/scan_localizer.h"

namespace pf_ros {
namespace {

template <typename Params>
std::set<std::string> namesOf(const Params& params) {
  std::set<std::string> names;
  for (const auto& p : params) names.insert(p.name);
  return names;
}

dynamic_reconfigure::Config request(const std::string& name, double value) {
  dynamic_reconfigure::Config msg;
  msg.doubles.emplace_back();
  msg.doubles.back().name = name;
  msg.doubles.back().value = value;
  return msg;
}

dynamic_reconfigure::Config request(const std::string& name, int value) {
  dynamic_reconfigure::Config msg;
  msg.ints.emplace_back();
  msg.ints.back().name = name;
  msg.ints.back().value = value;
  return msg;
}

TEST(LiveParams, TheCfgListsExactlyTheLiveParamsKldZAndRestoreDefaults) {
  dynamic_reconfigure::Config msg;
  pf_localization::PfLocalizationConfig::__getDefault__().__toMessage__(msg);
  std::set<std::string> cfg = namesOf(msg.doubles);
  for (const std::string& n : namesOf(msg.ints)) cfg.insert(n);
  for (const std::string& n : namesOf(msg.bools)) cfg.insert(n);
  const std::vector<std::string> names = liveParamNames();
  std::set<std::string> live(names.begin(), names.end());
  live.insert("kld_z");
  live.insert("restore_defaults");
  EXPECT_EQ(cfg, live);
  // And the message of a configuration fills every field of the generated type.
  // (From the defaults: the generated type leaves its fields uninitialised,
  // and fromMessage reads each one before it writes it.)
  pf_localization::PfLocalizationConfig config =
      pf_localization::PfLocalizationConfig::__getDefault__();
  dynamic_reconfigure::Config ours = liveParamsMessage(LocalizerConfig());
  EXPECT_TRUE(config.__fromMessage__(ours));
}

TEST(LiveParams, CfgDefaultsAreConfigPfYamls) {
  const LocalizerConfig yaml = readConfig(*yamlParamSource(PF_SOURCE_DIR "/config/pf.yaml"));
  dynamic_reconfigure::Config defaults;
  pf_localization::PfLocalizationConfig::__getDefault__().__toMessage__(defaults);
  const dynamic_reconfigure::Config ours = liveParamsMessage(yaml);
  for (const auto& d : defaults.doubles) {
    const auto it = std::find_if(ours.doubles.begin(), ours.doubles.end(),
                                 [&](const auto& o) { return o.name == d.name; });
    ASSERT_NE(it, ours.doubles.end()) << d.name;
    EXPECT_NEAR(it->value, d.value, 1e-9 * std::max(1.0, std::fabs(d.value))) << d.name;
  }
  for (const auto& d : defaults.ints) {
    const auto it = std::find_if(ours.ints.begin(), ours.ints.end(),
                                 [&](const auto& o) { return o.name == d.name; });
    ASSERT_NE(it, ours.ints.end()) << d.name;
    EXPECT_EQ(it->value, d.value) << d.name;
  }
  for (const auto& d : defaults.bools) {
    const auto it = std::find_if(ours.bools.begin(), ours.bools.end(),
                                 [&](const auto& o) { return o.name == d.name; });
    ASSERT_NE(it, ours.bools.end()) << d.name;
    EXPECT_EQ(it->value, d.value) << d.name;
  }
}

TEST(LiveParams, AcceptedChangeListsWhatChanged) {
  const LocalizerConfig current;
  dynamic_reconfigure::Config msg = liveParamsMessage(current);
  for (auto& d : msg.doubles) {
    if (d.name == "odom_alpha1") d.value = 0.5;
  }
  for (auto& i : msg.ints) {
    if (i.name == "max_particles") i.value = 60000;
  }
  const LiveChange change = applyLiveParams(current, msg);
  EXPECT_EQ(change.error, "");
  EXPECT_EQ(change.config.filter.motion.alpha1, 0.5);
  EXPECT_EQ(change.config.filter.kld.max_particles, 60000);
  EXPECT_EQ(change.changed,
            (std::vector<std::string>{"max_particles 50000 -> 60000", "odom_alpha1 0.2 -> 0.5"}));
  // The whole message of the current values changes nothing.
  EXPECT_TRUE(applyLiveParams(current, liveParamsMessage(current)).changed.empty());
}

TEST(LiveParams, InvalidValuesGetTheStartUpMessage) {
  const LocalizerConfig current;
  EXPECT_EQ(applyLiveParams(current, request("laser_sigma_hit", -1.0)).error,
            "invalid parameter laser_sigma_hit = -1: must be > 0 (m)");
  EXPECT_EQ(applyLiveParams(current, request("min_particles", 70000)).error,
            "invalid parameter max_particles = 50000: must be >= min_particles (70000)");
  EXPECT_EQ(applyLiveParams(current, request("transform_tolerance", -0.5)).error,
            "invalid parameter transform_tolerance = -0.5: must be >= 0 (s)");
}

TEST(LiveParams, AmclsKldZSetsKldConfidence) {
  const LocalizerConfig current;
  const LiveChange change = applyLiveParams(current, request("kld_z", 3.0));
  EXPECT_EQ(change.error, "");
  EXPECT_NEAR(change.config.filter.kld.confidence, 0.99865, 1e-5);
  EXPECT_EQ(
      change.changed,
      (std::vector<std::string>{"kld_confidence 0.99 -> 0.99865 (amcl's kld_z 2.32635 -> 3)"}));
  // kld_confidence itself wins over a kld_z that moved with it.
  dynamic_reconfigure::Config both = request("kld_confidence", 0.95);
  both.doubles.push_back(request("kld_z", 3.0).doubles.front());
  EXPECT_EQ(applyLiveParams(current, both).config.filter.kld.confidence, 0.95);
}

TEST(LiveParams, NegativeRangesMeanTheScansOwnAsAtStartUp) {
  const LiveChange change = applyLiveParams(LocalizerConfig(), request("laser_max_range", -1.0));
  EXPECT_EQ(change.error, "");
  EXPECT_EQ(change.config.filter.sensor.range_max, 0.0);
  EXPECT_TRUE(change.changed.empty());  // 0 already: nothing changes
}

TEST(LiveParams, TheFilterKeepsItsParticlesThroughAChange) {
  LocalizerConfig config;
  config.filter.kld.min_particles = 100;
  config.filter.kld.max_particles = 200;
  pf::ParticleFilter filter(config.filter);
  filter.setMap(pf::OccupancyGrid(20, 20, 0.1, {}, std::vector<int8_t>(400, 0)));
  filter.initializeGaussian({1.0, 1.0, 0.0}, Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal());
  const std::vector<double> x = filter.particles().x;
  const pf::Pose2 estimate = filter.estimate().pose;

  pf::ParticleFilterParams next = config.filter;
  next.kld.max_particles = 5000;  // reserves more under the live particles
  next.sensor.sigma_hit = 0.1;
  next.sensor.max_distance = 0.5;  // rebuilds the likelihood field
  next.motion.alpha1 = 0.4;
  filter.setParams(next);
  EXPECT_EQ(filter.particles().x, x);
  EXPECT_EQ(filter.estimate().pose.x, estimate.x);
  EXPECT_EQ(filter.params().kld.max_particles, 5000);
  EXPECT_EQ(filter.params().sensor.sigma_hit, 0.1);
  EXPECT_DOUBLE_EQ(filter.map()->resolution(), 0.1);  // the same map under the new field

  // An invalid set throws and changes nothing.
  pf::ParticleFilterParams bad = next;
  bad.sensor.sigma_hit = -1.0;
  bad.motion.alpha1 = 0.9;
  EXPECT_THROW(filter.setParams(bad), std::invalid_argument);
  EXPECT_EQ(filter.params().sensor.sigma_hit, 0.1);
  EXPECT_EQ(filter.params().motion.alpha1, 0.4);
  EXPECT_EQ(filter.particles().x, x);
}

TEST(LiveParams, ScanLocalizerTakesOnlyTheLiveParams) {
  LocalizerConfig config;
  config.filter.kld.min_particles = config.filter.kld.max_particles = 100;
  tf2::BufferCore tf;
  ScanLocalizer localizer(config, &tf);
  LocalizerConfig next = config;
  next.transform_tolerance = 0.3;
  next.filter.motion.alpha2 = 0.7;
  next.odom_frame = "elsewhere";  // not live: stays
  EXPECT_EQ(localizer.reconfigure(next), "");
  EXPECT_EQ(localizer.config().transform_tolerance, 0.3);
  EXPECT_EQ(localizer.filter().params().motion.alpha2, 0.7);
  EXPECT_EQ(localizer.config().odom_frame, "odom");
  next.filter.kld.min_particles = 1000;
  EXPECT_EQ(localizer.reconfigure(next),
            "invalid parameter max_particles = 100: must be >= min_particles (1000)");
  EXPECT_EQ(localizer.filter().params().kld.min_particles, 100);
}

}  // namespace
}  // namespace pf_ros

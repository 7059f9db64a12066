#include "pf_localization/ros/diagnostics.h"

#include <gtest/gtest.h>

#include <map>

namespace pf_ros {
namespace {

std::map<std::string, std::string> values(const diagnostic_msgs::DiagnosticStatus& s) {
  std::map<std::string, std::string> out;
  for (const auto& kv : s.values) out[kv.key] = kv.value;
  return out;
}

pf::ParticleFilterParams smallFilter() {
  pf::ParticleFilterParams p;
  p.kld.min_particles = p.kld.max_particles = 100;
  return p;
}

TEST(Diagnostics, FreshlyInitialisedFilterIsUncertainWithItsReason) {
  pf::ParticleFilter filter(smallFilter());
  filter.setMap(pf::OccupancyGrid(10, 10, 0.1, {}, std::vector<int8_t>(100, 0)));
  filter.initializeGaussian({0.5, 0.5, 0.0}, Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal());
  pf::UpdateReport report;
  report.ess = 42.0;
  const auto status = toDiagnosticStatus(filter, report, "pf_node: localization");
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(status.name, "pf_node: localization");
  EXPECT_EQ(status.message, "uncertain: no scan since the initialisation");
  const auto v = values(status);
  EXPECT_EQ(v.at("state"), "uncertain");
  EXPECT_EQ(v.at("particles"), "100");
  EXPECT_EQ(v.at("effective_sample_size"), "42");
  EXPECT_EQ(v.count("hit_fraction"), 1u);
  EXPECT_EQ(v.count("rival_clusters"), 1u);
}

TEST(Diagnostics, ShowsTheParametersInEffectAndTheirGeneration) {
  pf::ParticleFilterParams params = smallFilter();
  params.kld.max_particles = 1000000;
  params.motion.alpha1 = 0.35;
  params.sensor.sigma_hit = 0.15;
  pf::ParticleFilter filter(params);
  const auto v = values(toDiagnosticStatus(filter, pf::UpdateReport(), "x", 3));
  EXPECT_EQ(v.at("config_generation"), "3");
  EXPECT_EQ(v.at("max_particles"), "1000000");  // in full, not 1e+06
  EXPECT_EQ(v.at("odom_alpha1"), "0.35");
  EXPECT_EQ(v.at("laser_sigma_hit"), "0.15");
}

TEST(Diagnostics, UninitialisedFilterIsLost) {
  pf::ParticleFilter filter(smallFilter());
  const auto status = toDiagnosticStatus(filter, pf::UpdateReport(), "x");
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_EQ(values(status).at("state"), "lost");
}

TEST(Diagnostics, SeveralSensorsAreListedAndAMissingOneNamed) {
  diagnostic_msgs::DiagnosticStatus status;
  status.level = diagnostic_msgs::DiagnosticStatus::OK;
  status.message = "localized: fits";
  pf::SensorHealth health({"scan_front", "scan_rear"});
  for (int i = 0; i <= 10; ++i) {
    health.observe(0, 0.1 * i, 541, 0, 0.0);  // covered
    health.observe(1, 0.1 * i, 541, 530, 0.9);
  }
  addSensors(&status, health, 1.0);
  EXPECT_EQ(diagnostic_msgs::DiagnosticStatus::WARN, status.level);
  EXPECT_EQ("localized: fits; missing: scan_front (blocked: 0 % of its beams read)",
            status.message);
  std::map<std::string, std::string> values;
  for (const auto& kv : status.values) values[kv.key] = kv.value;
  EXPECT_EQ("ok, 10.0 Hz, 0.00 s old, 98 % readings, 90 % fit", values["sensor scan_rear"]);
  EXPECT_EQ(1u, values.count("sensor scan_front"));
  // One sensor: nothing to add.
  diagnostic_msgs::DiagnosticStatus one;
  addSensors(&one, pf::SensorHealth({"scan"}), 1.0);
  EXPECT_TRUE(one.values.empty());
}

}  // namespace
}  // namespace pf_ros

#include "pf_localization/ros/diagnostics/diagnostic_status.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "support/rooms.h"
#include "support/scan_simulator.h"

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

pf::Hypothesis hypothesis(double x, double y, double weight) {
  pf::Hypothesis h;
  h.pose = {x, y, M_PI / 2};
  h.weight = weight;
  h.covariance.diagonal() << 0.04, 0.01, 0.0025;
  h.particles = 800;
  return h;
}

TEST(Diagnostics, SeveralHypothesesAreCountedAndNamedHeaviestFirst) {
  diagnostic_msgs::DiagnosticStatus status;
  status.message = "uncertain: 1 rival hypothesis elsewhere";
  pf::Hypotheses twins;
  twins.count = 2;
  twins.listed = {hypothesis(1.2, 7.6, 0.52), hypothesis(11.246, 7.6, 0.47)};
  addHypotheses(&status, twins);
  EXPECT_EQ(
      "uncertain: 1 rival hypothesis elsewhere; 2 hypotheses: (1.20, 7.60) 52 %, (11.25, 7.60) "
      "47 %",
      status.message);
  const auto v = values(status);
  EXPECT_EQ("2", v.at("hypotheses"));
  EXPECT_EQ(
      "x 11.25 m, y 7.60 m, yaw 90 deg, 47 % of the weight, std 0.20 m, 0.10 m, 3 deg, 800 "
      "particles",
      v.at("hypothesis 2"));
  EXPECT_EQ(1u, v.count("hypothesis 1"));
}

TEST(Diagnostics, ManyHypothesesNameTheFirstFewAndListEveryOne) {
  diagnostic_msgs::DiagnosticStatus status;
  pf::Hypotheses aisles;
  aisles.count = 10;
  for (int k = 0; k < 10; ++k) aisles.listed.push_back(hypothesis(2.0 * k, 5.0, 0.1));
  addHypotheses(&status, aisles);
  EXPECT_EQ(
      "; 10 hypotheses: (0.00, 5.00) 10 %, (2.00, 5.00) 10 %, (4.00, 5.00) 10 %, (6.00, 5.00) "
      "10 %, ...",
      status.message);
  EXPECT_EQ(1u, values(status).count("hypothesis 10"));
}

TEST(Diagnostics, OneHypothesisIsACountAndNothingElse) {
  diagnostic_msgs::DiagnosticStatus status;
  status.message = "localized: 95 % of the beams fit, one hypothesis";
  pf::Hypotheses one;
  one.count = 1;
  one.listed = {hypothesis(3.0, 4.0, 1.0)};
  addHypotheses(&status, one);
  EXPECT_EQ("localized: 95 % of the beams fit, one hypothesis", status.message);
  ASSERT_EQ(1u, status.values.size());
  EXPECT_EQ("1", values(status).at("hypotheses"));
}

TEST(Diagnostics, TheMapsChangesAreTheLayersCounts) {
  // A room whose map has a box the world lacks, toured twice.
  const pf::test::Box box{0.8, 1.8, 1.2, 2.2};
  const pf::OccupancyGrid map = pf::test::room(4.0, 3.0, 0.05, {box});
  const pf::DistanceField field(map, 2.0);
  pf::MapChangeLayer layer(field);
  pf::test::ScanSpec spec;
  spec.beams = 360;
  spec.angle_increment = 2.0 * M_PI / 360;
  for (int k = 0; k < 2; ++k) {
    for (const pf::Pose2& p : {pf::Pose2{2.0, 1.5, 0.0}, pf::Pose2{2.5, 2.0, -2.0}}) {
      layer.add(pf::test::simulateScan(pf::test::room(4.0, 3.0, 0.05), p, spec), p);
    }
  }
  const pf::MapChangeLayer::Summary s = layer.summary();
  ASSERT_GT(s.removed, 0u);
  diagnostic_msgs::DiagnosticStatus status;
  addMapChanges(&status, &layer);
  const auto v = values(status);
  EXPECT_EQ(v.at("map_cells_seen"), std::to_string(s.seen));
  EXPECT_EQ(v.at("map_cells_new"), "0");
  EXPECT_EQ(v.at("map_cells_gone"), std::to_string(s.removed));
  // Each gone cell was passed by 2 to 4 scans: the mean lies between.
  const double mean = std::stod(v.at("map_gone_mean_scans"));
  EXPECT_GE(mean, 2.0);
  EXPECT_LE(mean, 4.0);
  EXPECT_NE(v.at("map changes")
                .find("0 cells new, " + std::to_string(s.removed) + " gone, of " +
                      std::to_string(s.seen) + " seen, from 4 scans"),
            std::string::npos)
      << v.at("map changes");
  diagnostic_msgs::DiagnosticStatus none;
  addMapChanges(&none, nullptr);
  EXPECT_TRUE(none.values.empty());
}

}  // namespace
}  // namespace pf_ros

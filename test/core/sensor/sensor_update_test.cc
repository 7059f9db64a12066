// SensorUpdate (the weighing of the particles by a scan) and the choice of
// how cautiously to weigh it (temperingEssFraction).
#include "pf_localization/core/sensor/sensor_update.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numeric>

#include "core/small_world.h"
#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/core/filter/weighting.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"

namespace pf {
namespace {

const LikelihoodFieldModel& fieldModel(const SensorUpdate& sensor) {
  return dynamic_cast<const LikelihoodFieldModel&>(sensor.model());
}

TEST(SensorUpdate, TheTablesOfTheRangesExpectedAreBuiltWithTheModel) {
  const OccupancyGrid grid = small_world::room();
  SensorUpdate sensor;
  // Seen before there is a map: a front lidar of 25 m and a rear one of
  // 12 m, and what is not a range at all.
  sensor.expectRange(25.0);
  sensor.expectRange(12.0);
  sensor.expectRange(25.0);
  sensor.expectRange(std::nan(""));
  sensor.expectRange(0.0);
  sensor.setModel(std::make_unique<LikelihoodFieldModel>(grid, LikelihoodFieldModelParams()));
  EXPECT_EQ(2u, fieldModel(sensor).tablesBuilt());
  // Weighing their scans builds nothing more.
  ParticleSet particles;
  particles.resize(1);
  particles.setPose(0, small_world::kTruth);
  particles.setUniformWeights();
  LaserScan scan = small_world::castScan(grid, small_world::kTruth);
  for (double range_max : {25.0, 12.0}) {
    scan.range_max = range_max;
    sensor.weigh(sensor.model().prepare(scan), 0.0, 1.0, &particles);
  }
  EXPECT_EQ(2u, fieldModel(sensor).tablesBuilt());
  // A new map's model is warmed up for the same two.
  sensor.setModel(std::make_unique<LikelihoodFieldModel>(grid, LikelihoodFieldModelParams()));
  EXPECT_EQ(2u, fieldModel(sensor).tablesBuilt());
  // A third range, with a model: built at once.
  sensor.expectRange(8.0);
  EXPECT_EQ(3u, fieldModel(sensor).tablesBuilt());
}

TEST(SensorUpdate, OnlyTheLatestRangesAreKeptForTheNextModel) {
  const OccupancyGrid grid = small_world::room();
  SensorUpdate sensor;
  for (int r = 1; r <= 6; ++r) sensor.expectRange(4.0 * r);
  sensor.setModel(std::make_unique<LikelihoodFieldModel>(grid, LikelihoodFieldModelParams()));
  EXPECT_EQ(LikelihoodTables::kMaxTables, fieldModel(sensor).tablesBuilt());
}

TEST(SensorUpdate, TheParticleAtTheTruthWinsAndTheWeightsAreNormalised) {
  const OccupancyGrid grid = small_world::room();
  SensorUpdate sensor;
  EXPECT_FALSE(sensor.hasModel());
  EXPECT_EQ(nullptr, sensor.get());
  sensor.setModel(std::make_unique<LikelihoodFieldModel>(grid, LikelihoodFieldModelParams()));
  ASSERT_TRUE(sensor.hasModel());
  sensor.reserve(1000);

  ParticleSet particles;
  particles.resize(3);
  particles.setPose(0, compose(small_world::kTruth, {0.3, 0.0, 0.0}));
  particles.setPose(1, small_world::kTruth);
  particles.setPose(2, compose(small_world::kTruth, {0.0, 0.0, 0.4}));
  particles.setUniformWeights();
  const PreparedScan scan =
      sensor.model().prepare(small_world::castScan(grid, small_world::kTruth));
  const Weighing w = sensor.weigh(scan, 0.0, 1.0, &particles);
  EXPECT_EQ(1.0, w.tempering);  // 0: no tempering
  EXPECT_EQ(0, w.beams_skipped);
  EXPECT_GT(particles.weight[1], particles.weight[0]);
  EXPECT_GT(particles.weight[1], particles.weight[2]);
  EXPECT_NEAR(1.0, std::accumulate(particles.weight.begin(), particles.weight.end(), 0.0), 1e-12);
  EXPECT_GT(w.mean_beam_likelihood, 0.0);
}

TEST(SensorUpdate, StrongEvidenceIsTemperedToKeepTheAskedESS) {
  const OccupancyGrid grid = small_world::room();
  SensorUpdate sensor;
  sensor.setModel(std::make_unique<LikelihoodFieldModel>(grid, LikelihoodFieldModelParams()));
  ParticleSet particles;
  particles.resize(100);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    particles.setPose(i, compose(small_world::kTruth, {0.01 * static_cast<double>(i), 0.0, 0.0}));
  }
  particles.setUniformWeights();
  const PreparedScan scan =
      sensor.model().prepare(small_world::castScan(grid, small_world::kTruth));
  const Weighing w = sensor.weigh(scan, 0.5, 1.0, &particles);
  EXPECT_LT(w.tempering, 1.0);
  EXPECT_GE(effectiveSampleSize(particles.weight), 0.5 * 100 - 1.0);
}

// An update that brings a share s of a new view weighs by the likelihood
// to the power s; one that brings none leaves the weights, and its mean
// beam likelihood is the scan's own either way.
TEST(SensorUpdate, APartialViewWeighsByItsShareOfTheLikelihood) {
  const OccupancyGrid grid = small_world::room();
  SensorUpdate sensor;
  sensor.setModel(std::make_unique<LikelihoodFieldModel>(grid, LikelihoodFieldModelParams()));
  const std::vector<PreparedScan> scans = {
      sensor.model().prepare(small_world::castScan(grid, small_world::kTruth))};
  const auto weighed = [&](double share, Weighing* w) {
    ParticleSet particles;
    particles.resize(2);
    particles.setPose(0, small_world::kTruth);
    particles.setPose(1, compose(small_world::kTruth, {0.1, 0.0, 0.0}));
    particles.setUniformWeights();
    *w = sensor.weigh(sensor.model(), scans, 0.0, 1.0, &particles, 1, share);
    return std::log(particles.weight[0] / particles.weight[1]);
  };
  Weighing whole, half, none;
  const double log_ratio = weighed(1.0, &whole);
  ASSERT_GT(log_ratio, 1.0);
  EXPECT_NEAR(0.5 * log_ratio, weighed(0.5, &half), 1e-9);
  EXPECT_DOUBLE_EQ(0.0, weighed(0.0, &none));
  EXPECT_DOUBLE_EQ(0.5, half.tempering);
  EXPECT_DOUBLE_EQ(0.0, none.tempering);
  // The fit is the scan's, whatever share of it the weights took.
  EXPECT_GT(whole.mean_beam_likelihood, 0.0);
  EXPECT_NEAR(whole.mean_beam_likelihood, half.mean_beam_likelihood,
              0.2 * whole.mean_beam_likelihood);
  ASSERT_TRUE(std::isfinite(none.mean_beam_likelihood));
  EXPECT_GT(none.mean_beam_likelihood, 0.0);
}

TEST(TemperingEssFraction, CautiousUnlessLocalizedOrOnlySpread) {
  ParticleFilterParams p;
  p.tempering_ess_fraction = 0.02;
  p.tempering_ess_fraction_uncertain = 0.1;
  Confidence last;
  last.rivals = 0;
  last.hit_fraction = 0.9;  // above localized_hit_fraction 0.75
  EXPECT_EQ(0.02, temperingEssFraction(LocalizationState::kLocalized, last, p));
  EXPECT_EQ(0.02, temperingEssFraction(LocalizationState::kUncertain, last, p));  // only spread
  EXPECT_EQ(0.1, temperingEssFraction(LocalizationState::kLost, last, p));
  Confidence rivals = last;
  rivals.rivals = 1;
  EXPECT_EQ(0.1, temperingEssFraction(LocalizationState::kUncertain, rivals, p));
  Confidence poor = last;
  poor.hit_fraction = 0.6;
  EXPECT_EQ(0.1, temperingEssFraction(LocalizationState::kUncertain, poor, p));
}

}  // namespace
}  // namespace pf

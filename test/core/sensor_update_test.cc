// SensorUpdate (the weighing of the particles by a scan) and the choice of
// how cautiously to weigh it (temperingEssFraction).
#include "pf_localization/core/sensor_update.h"

#include <gtest/gtest.h>

#include <memory>
#include <numeric>

#include "pf_localization/core/likelihood_field_model.h"
#include "pf_localization/core/resampler.h"
#include "pf_localization/core/tempering.h"
#include "small_world.h"

namespace pf {
namespace {

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

// GlobalSearch: the smoothing a sparse cloud's density asks for, the support
// read from KLD's bins, when the search hands over to the sensor model, and
// the cautious tempering until the cloud is localized.
#include "pf_localization/core/recovery/global_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/small_world.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/recovery/recovery.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/util/random.h"
#include "support/rooms.h"

namespace pf {
namespace {

TEST(SearchSmoothing, PutsTheWantedParticlesWithinReachOfEveryPose) {
  // 1 000 000 particles over the simulated warehouse's 9 000 m^2, a 5 m
  // median range: 4 s^2 * 2 s / r * N / V = kParticlesInReach.
  const double support = 9000.0 * 2.0 * M_PI;
  const double s = searchSmoothing(1e6, support, 5.0);
  EXPECT_NEAR(kParticlesInReach, 8.0 * s * s * s / 5.0 * 1e6 / support, 1e-9);
  EXPECT_NEAR(0.56, s, 0.01);
  // Eight times the particles halve it; a longer range widens it.
  EXPECT_NEAR(s / 2.0, searchSmoothing(8e6, support, 5.0), 1e-12);
  EXPECT_GT(searchSmoothing(1e6, support, 10.0), s);
  // Wider than pi r every heading is within reach: 8 pi s^2 * N / V.
  const double wide = searchSmoothing(10.0, support, 0.5);
  EXPECT_GT(wide, M_PI * 0.5);
  EXPECT_NEAR(kParticlesInReach, 8.0 * M_PI * wide * wide * 10.0 / support, 1e-9);
  EXPECT_EQ(0.0, searchSmoothing(0.0, support, 5.0));
}

TEST(SupportOfBins, ReadsTheSpreadOfUniformParticlesFromTheOccupiedBins) {
  // 20 000 particles dropped at random into 30 000 bins occupy about
  // 30 000 (1 - e^(-2/3)) = 14 600 of them: the support is read back.
  Random random(7);
  const std::size_t bins = 30000, particles = 20000;
  std::vector<bool> occupied(bins, false);
  for (std::size_t i = 0; i < particles; ++i) {
    occupied[static_cast<std::size_t>(random.uniform() * bins) % bins] = true;
  }
  double k = 0.0;
  for (bool o : occupied) k += o ? 1.0 : 0.0;
  const double volume = 0.01;
  EXPECT_NEAR(bins * volume, supportOfBins(k, particles, volume, 1e6), 0.03 * bins * volume);
  // Every particle in a bin of its own says nothing of the spacing: the cap.
  EXPECT_EQ(500.0, supportOfBins(particles, particles, volume, 500.0));
  // Many particles to a bin: about the bins themselves.
  EXPECT_NEAR(100 * volume, supportOfBins(100, 100000, volume, 1e6), 1e-6);
}

TEST(LikelihoodFieldModel, ASmoothedCopySharesTheFieldAndForgivesAnOffsetEndPoint) {
  const OccupancyGrid grid = small_world::room();
  const LikelihoodFieldModel model(grid, LikelihoodFieldModelParams{});
  const std::unique_ptr<SensorModel> smooth = model.smoothed(0.8);
  ASSERT_TRUE(smooth);
  EXPECT_EQ(&model.field(), &smooth->field());
  const PreparedScan scan = model.prepare(small_world::castScan(grid, small_world::kTruth));
  const Pose2 off = compose(small_world::kTruth, {0.3, 0.0, 0.0});
  // The sharp model loses more than twice as much for 0.3 m (28.8 against
  // 12.9, likelihood_exponent 0.2 included).
  const double sharp_loss =
      model.logLikelihood(scan, small_world::kTruth) - model.logLikelihood(scan, off);
  const double smooth_loss =
      smooth->logLikelihood(scan, small_world::kTruth) - smooth->logLikelihood(scan, off);
  EXPECT_GT(smooth_loss, 0.0);
  EXPECT_GT(sharp_loss, 2.0 * smooth_loss);
}

class GlobalSearchTest : public ::testing::Test {
 protected:
  // `n` particles drawn over the room's free space.
  ParticleSet uniform(std::size_t n) {
    ParticleSet set;
    set.resize(n);
    Random random(3);
    for (std::size_t i = 0; i < n; ++i) set.setPose(i, randomFreePose(grid_, &random));
    set.setUniformWeights();
    return set;
  }
  double freeArea() const {
    return static_cast<double>(grid_.freeCells().size()) * grid_.resolution() * grid_.resolution();
  }

  const OccupancyGrid grid_ = test::tenMetreRoom();
  const LikelihoodFieldModelParams params_{};
  const LikelihoodFieldModel model_{grid_, params_};
  const std::vector<PreparedScan> scans_{
      model_.prepare(small_world::castScan(grid_, {5.0, 5.0, 0.0}))};
  GlobalSearch search_;
};

TEST_F(GlobalSearchTest, ASparseCloudIsWeighedByAWiderLikelihoodUntilItIsDense) {
  EXPECT_EQ(nullptr, search_.model(model_, params_.sigma_hit, params_.max_distance, scans_,
                                   uniform(1000), KldParams{}, 1))
      << "no search before a global initialisation";
  EXPECT_EQ(0.0, search_.minEssFraction());
  search_.start(freeArea());
  // 100 m^2 of free space, 5 m ranges: 50 000 particles ask for s of about
  // 0.3 m, rounded up to 0.2 * sqrt(2)^2.
  const SensorModel* smooth = search_.model(model_, params_.sigma_hit, params_.max_distance, scans_,
                                            uniform(50000), KldParams{}, 1);
  ASSERT_NE(nullptr, smooth);
  EXPECT_DOUBLE_EQ(0.4, search_.sigma());
  EXPECT_TRUE(search_.smoothing());
  EXPECT_EQ(0.0, search_.minEssFraction());
  // A cloud gathered at one place is dense enough: the model's own, for good.
  ParticleSet tight;
  tight.resize(5000);
  for (std::size_t i = 0; i < tight.size(); ++i) {
    tight.setPose(i, {5.0 + 1e-4 * static_cast<double>(i % 10), 5.0, 0.0});
  }
  tight.setUniformWeights();
  EXPECT_EQ(nullptr, search_.model(model_, params_.sigma_hit, params_.max_distance, scans_, tight,
                                   KldParams{}, 1));
  EXPECT_EQ(0.0, search_.sigma());
  EXPECT_FALSE(search_.smoothing());
  // The cloud settles: tempered more cautiously until it is localized.
  EXPECT_EQ(kSettlingEssFraction, search_.minEssFraction());
  search_.observe(2);  // two look-alike places
  EXPECT_EQ(kSettlingEssFraction, search_.minEssFraction());
  search_.observe(1);
  EXPECT_EQ(0.0, search_.minEssFraction());
  EXPECT_EQ(nullptr, search_.model(model_, params_.sigma_hit, params_.max_distance, scans_,
                                   uniform(50000), KldParams{}, 1));
}

TEST_F(GlobalSearchTest, ACloudTooSparseForTheMapsContrastKeepsTheModel) {
  // 500 particles over 100 m^2 would need s of about 1.4 m, beyond
  // kMaxSearchSmoothing of the 2 m distance cap: the model and tempering
  // as they were, rather than a likelihood that says little but "open space".
  search_.start(freeArea());
  EXPECT_EQ(nullptr, search_.model(model_, params_.sigma_hit, params_.max_distance, scans_,
                                   uniform(500), KldParams{}, 1));
  EXPECT_FALSE(search_.smoothing());
  EXPECT_EQ(kSettlingEssFraction, search_.minEssFraction());
}

TEST(ParticleFilterSearch, OnlyAGlobalInitialisationSearches) {
  const OccupancyGrid grid = test::tenMetreRoom();
  ParticleFilterParams params;
  params.update_min_d = params.update_min_a = 0.0;
  ParticleFilter filter(params);
  filter.setMap(grid);
  const LaserScan scan = small_world::castScan(grid, {5.0, 5.0, 0.0});
  filter.initializeUniform();
  EXPECT_GT(filter.update({0.0, 0.0, 0.0}, scan).search_sigma, params.sensor.sigma_hit);
  filter.initializeGaussian({5.0, 5.0, 0.0}, Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal());
  EXPECT_EQ(0.0, filter.update({0.01, 0.0, 0.0}, scan).search_sigma);
}

}  // namespace
}  // namespace pf

#include "pf_localization/core/filter/resampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace pf {
namespace {

// Particle i sits at x = i, so survivors can be traced back to their source.
ParticleSet labelled(const std::vector<double>& weights) {
  ParticleSet set;
  set.resize(weights.size());
  for (std::size_t i = 0; i < weights.size(); ++i) {
    set.setPose(i, {static_cast<double>(i), -static_cast<double>(i), 0.01 * i});
    set.weight[i] = weights[i];
  }
  return set;
}

std::vector<int> survivorCounts(const ParticleSet& set, std::size_t sources) {
  std::vector<int> counts(sources, 0);
  for (std::size_t i = 0; i < set.size(); ++i) {
    const auto src = static_cast<std::size_t>(set.x[i]);
    EXPECT_EQ(static_cast<double>(src), set.x[i]);
    EXPECT_EQ(-static_cast<double>(src), set.y[i]);  // the whole pose is copied
    EXPECT_EQ(0.01 * src, set.yaw[i]);
    ++counts.at(src);
  }
  return counts;
}

TEST(EffectiveSampleSize, ExactValues) {
  EXPECT_DOUBLE_EQ(4.0, effectiveSampleSize({0.25, 0.25, 0.25, 0.25}));
  EXPECT_DOUBLE_EQ(1.0, effectiveSampleSize({1.0, 0.0, 0.0, 0.0}));
  EXPECT_DOUBLE_EQ(2.0, effectiveSampleSize({0.5, 0.5, 0.0, 0.0}));
  // 1 / (0.25 + 0.0625 + 0.0625) = 1 / 0.375 = 8/3.
  EXPECT_DOUBLE_EQ(8.0 / 3.0, effectiveSampleSize({0.5, 0.25, 0.25, 0.0}));
  // One 0.9 and ten 0.01: 1 / (0.9^2 + 10 * 0.01^2) = 1 / 0.811.
  std::vector<double> skewed(10, 0.01);
  skewed.push_back(0.9);
  EXPECT_NEAR(1.0 / 0.811, effectiveSampleSize(skewed), 1e-12);
  EXPECT_EQ(0.0, effectiveSampleSize({}));
  EXPECT_EQ(0.0, effectiveSampleSize({0.0, 0.0}));
}

TEST(SystematicResample, DeterministicWeightsGiveExactCountsForAnyOffset) {
  // With 4 survivors the pointers are u, u + 1/4, u + 1/2, u + 3/4 for some
  // u in [0, 1/4): two fall in [0, 0.5), one in [0.5, 0.75), one in [0.75, 1).
  for (uint64_t seed = 0; seed < 200; ++seed) {
    ParticleSet set = labelled({0.5, 0.25, 0.25, 0.0});
    Random random(seed);
    systematicResample(&set, 4, &random);
    ASSERT_EQ(4u, set.size());
    EXPECT_EQ((std::vector<int>{2, 1, 1, 0}), survivorCounts(set, 4)) << "seed " << seed;
    // Survivors come out in source order, with uniform weights.
    EXPECT_EQ((std::vector<double>{0, 0, 1, 2}), set.x);
    EXPECT_EQ(std::vector<double>(4, 0.25), set.weight);
  }
}

TEST(SystematicResample, ChangesTheParticleCount) {
  for (uint64_t seed = 0; seed < 50; ++seed) {
    Random random(seed);
    ParticleSet up = labelled({0.5, 0.25, 0.25, 0.0});
    systematicResample(&up, 8, &random);  // steps of 1/8: 4, 2, 2, 0
    EXPECT_EQ((std::vector<int>{4, 2, 2, 0}), survivorCounts(up, 4));
    EXPECT_EQ(std::vector<double>(8, 0.125), up.weight);

    ParticleSet down = labelled({0.5, 0.25, 0.25, 0.0});
    systematicResample(&down, 2, &random);  // u in [0, 0.5), u + 0.5 in [0.5, 1)
    const std::vector<int> counts = survivorCounts(down, 4);
    EXPECT_EQ(1, counts[0]);
    EXPECT_EQ(0, counts[3]);
    EXPECT_EQ(1, counts[1] + counts[2]);
  }
}

TEST(SystematicResample, UnnormalisedWeightsAreNormalised) {
  for (uint64_t seed = 0; seed < 50; ++seed) {
    ParticleSet set = labelled({2.0, 1.0, 1.0, 0.0});
    Random random(seed);
    systematicResample(&set, 4, &random);
    EXPECT_EQ((std::vector<int>{2, 1, 1, 0}), survivorCounts(set, 4));
  }
}

TEST(SystematicResample, CountsAreFloorOrCeilOfTheExpectedNumber) {
  // The property that makes systematic resampling low-variance: particle j
  // gets floor(n w_j) or ceil(n w_j) survivors, never more, never fewer.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> weight(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const std::size_t m = 1 + trial % 17, n = 1 + (trial * 7) % 50;
    std::vector<double> w(m);
    double total = 0.0;
    for (double& v : w) total += v = weight(rng);
    ParticleSet set = labelled(w);
    Random random(trial);
    systematicResample(&set, n, &random);
    ASSERT_EQ(n, set.size());
    const std::vector<int> counts = survivorCounts(set, m);
    for (std::size_t j = 0; j < m; ++j) {
      const double expected = n * w[j] / total;
      EXPECT_GE(counts[j], std::floor(expected) - 1e-9) << "trial " << trial << " j " << j;
      EXPECT_LE(counts[j], std::ceil(expected) + 1e-9) << "trial " << trial << " j " << j;
    }
  }
}

TEST(SystematicResample, ZeroWeightParticlesNeverSurvive) {
  for (uint64_t seed = 0; seed < 100; ++seed) {
    ParticleSet set = labelled({0.0, 0.3, 0.0, 0.0, 0.7, 0.0});
    Random random(seed);
    systematicResample(&set, 10, &random);
    EXPECT_EQ((std::vector<int>{0, 3, 0, 0, 7, 0}), survivorCounts(set, 6));
  }
}

TEST(SystematicResample, EmptyInOrOut) {
  Random random(1);
  ParticleSet set = labelled({0.5, 0.5});
  systematicResample(&set, 0, &random);
  EXPECT_TRUE(set.empty());
  EXPECT_TRUE(set.weight.empty());
  ParticleSet none;
  systematicResample(&none, 5, &random);
  EXPECT_TRUE(none.empty());
}

TEST(NormalQuantile, KnownValues) {
  EXPECT_NEAR(0.0, normalQuantile(0.5), 1e-12);
  EXPECT_NEAR(1.959963984540054, normalQuantile(0.975), 1e-9);
  EXPECT_NEAR(-1.959963984540054, normalQuantile(0.025), 1e-9);
  EXPECT_NEAR(2.326347874040841, normalQuantile(0.99), 1e-9);
  EXPECT_NEAR(-2.326347874040841, normalQuantile(0.01), 1e-9);  // the lower tail branch
  EXPECT_NEAR(1.0, normalQuantile(0.8413447460685429), 1e-9);
  EXPECT_NEAR(3.090232306167813, normalQuantile(0.999), 1e-9);  // the upper tail branch
  EXPECT_NEAR(-4.753424308822899, normalQuantile(1e-6), 1e-8);
  // Round trip through the CDF.
  for (double p = 0.001; p < 1.0; p += 0.0137) {
    EXPECT_NEAR(p, 0.5 * std::erfc(-normalQuantile(p) / std::sqrt(2.0)), 1e-12) << p;
  }
}

TEST(NormalQuantile, RejectsProbabilitiesOutsideTheOpenInterval) {
  EXPECT_THROW(normalQuantile(0.0), std::invalid_argument);
  EXPECT_THROW(normalQuantile(1.0), std::invalid_argument);
  EXPECT_THROW(normalQuantile(-0.1), std::invalid_argument);
  EXPECT_THROW(normalQuantile(std::nan("")), std::invalid_argument);
}

TEST(KldBound, ExactValue) {
  // k = 10, err = 0.05, confidence 0.99 (z = 2.326348):
  //   a = 2 / (9 * 9) = 0.0246914, b = 1 - a + sqrt(a) z = 1.3408589,
  //   n = 9 / (2 * 0.05) * b^3 = 90 * 2.4107339 = 216.96605.
  EXPECT_NEAR(216.96605313273434, kldBound(10, 0.05, 0.99), 1e-6);
  // k = 2, err = 0.01, confidence 0.5 (z = 0): a = 2/9, n = 1 / 0.02 * (7/9)^3 = 23.5330.
  EXPECT_NEAR(50.0 * 343.0 / 729.0, kldBound(2, 0.01, 0.5), 1e-9);
  // One bin or none needs one particle.
  EXPECT_EQ(1.0, kldBound(1, 0.01, 0.99));
  EXPECT_EQ(1.0, kldBound(0, 0.01, 0.99));
}

TEST(KldBound, GrowsWithBinsAndConfidenceAndShrinksWithError) {
  double previous = kldBound(2, 0.05, 0.99);
  for (std::size_t k = 3; k < 500; k += 7) {
    const double n = kldBound(k, 0.05, 0.99);
    EXPECT_GT(n, previous);
    previous = n;
  }
  EXPECT_GT(kldBound(50, 0.05, 0.999), kldBound(50, 0.05, 0.99));
  EXPECT_NEAR(kldBound(50, 0.01, 0.99), 5.0 * kldBound(50, 0.05, 0.99), 1e-9);
}

KldParams kld(int min_particles, int max_particles) {
  KldParams p;
  p.min_particles = min_particles;
  p.max_particles = max_particles;
  p.kld_err = 0.05;
  p.confidence = 0.99;
  p.bin_xy = 0.5;
  p.bin_yaw = 0.1745;
  return p;
}

// n particles with equal weights, each in its own bin (x = 1 m apart).
ParticleSet inSeparateBins(std::size_t n) {
  ParticleSet set;
  set.resize(n);
  for (std::size_t i = 0; i < n; ++i) set.setPose(i, {1.0 * i + 0.25, 0.25, 0.05});
  set.setUniformWeights();
  return set;
}

TEST(KldParticleCount, CountsOccupiedBins) {
  // 10 bins: ceil(216.966) = 217.
  EXPECT_EQ(217u, kldParticleCount(inSeparateBins(10), kld(1, 100000)));
  // Particles sharing bins do not add any: 10 bins of 3 particles each.
  ParticleSet shared;
  shared.resize(30);
  for (std::size_t i = 0; i < 30; ++i)
    shared.setPose(i, {1.0 * (i % 10) + 0.1 * (i / 10), 0.1, 0.0});
  shared.setUniformWeights();
  EXPECT_EQ(217u, kldParticleCount(shared, kld(1, 100000)));
  // The same in y and in yaw.
  ParticleSet yaw_bins = inSeparateBins(10);
  for (std::size_t i = 0; i < 10; ++i) yaw_bins.setPose(i, {0.1, 0.1, -1.5 + 0.3 * i});
  EXPECT_EQ(217u, kldParticleCount(yaw_bins, kld(1, 100000)));
}

TEST(KldParticleCount, BinsTooLightToSurviveDoNotCount) {
  // Eleven bins, but the eleventh holds weight 0.01 < 1/11: it would most
  // likely be empty after resampling, so k = 10.
  ParticleSet set = inSeparateBins(11);
  for (std::size_t i = 0; i < 10; ++i) set.weight[i] = 0.099;
  set.weight[10] = 0.01;
  EXPECT_EQ(217u, kldParticleCount(set, kld(1, 100000)));
}

TEST(KldParticleCount, ClampsToMinAndMax) {
  // One bin asks for 1 particle: raised to the minimum.
  ParticleSet one_bin = inSeparateBins(1);
  EXPECT_EQ(100u, kldParticleCount(one_bin, kld(100, 1000)));
  // Ten bins ask for 217: kept inside [100, 1000], raised to a minimum of
  // 300, capped by a maximum of 150.
  EXPECT_EQ(217u, kldParticleCount(inSeparateBins(10), kld(100, 1000)));
  EXPECT_EQ(300u, kldParticleCount(inSeparateBins(10), kld(300, 1000)));
  EXPECT_EQ(150u, kldParticleCount(inSeparateBins(10), kld(100, 150)));
  // An empty set asks for the minimum.
  EXPECT_EQ(100u, kldParticleCount(ParticleSet(), kld(100, 1000)));
  // A fixed budget, whatever the spread (one bin, ten, none).
  EXPECT_EQ(150u, kldParticleCount(one_bin, kld(150, 150)));
  EXPECT_EQ(150u, kldParticleCount(inSeparateBins(10), kld(150, 150)));
  EXPECT_EQ(150u, kldParticleCount(ParticleSet(), kld(150, 150)));
}

TEST(KldParticleCount, GrowsWithSpread) {
  std::size_t previous = 0;
  for (double sigma : {0.05, 0.3, 1.0, 3.0}) {
    std::mt19937 rng(17);
    std::normal_distribution<double> xy(0.0, sigma), yaw(0.0, sigma / 3);
    ParticleSet set;
    set.resize(2000);
    for (std::size_t i = 0; i < set.size(); ++i) set.setPose(i, {xy(rng), xy(rng), yaw(rng)});
    set.setUniformWeights();
    const std::size_t n = kldParticleCount(set, kld(10, 1000000));
    EXPECT_GT(n, previous) << "sigma " << sigma;
    previous = n;
  }
  EXPECT_GT(previous, 10000u);  // a wide cloud occupies well over a hundred bins
}

}  // namespace
}  // namespace pf

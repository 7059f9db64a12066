// Recovery and its strategies: how many random particles are injected and
// when the survivors are spread; and the resampling that carries it out.
#include "pf_localization/core/recovery/recovery.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "core/small_world.h"

namespace pf {
namespace {

RecoveryContext context(double slow, double fast, LocalizationState state) {
  RecoveryContext c;
  c.slow = c.slow_before = slow;
  c.fast = c.mean_beam_likelihood = fast;
  c.state = state;
  c.particles = 500;
  c.max_particles = 5000;
  c.has_free_space = true;
  return c;
}

TEST(AugmentedMclInjection, InjectsTheDipOnlyAfterPatience) {
  RecoveryParams p;  // trigger_ratio 0.7, patience 5, patience_localized 10
  AugmentedMclInjection injection;
  // The usual fit: nothing.
  RecoveryPlan plan;
  injection.contribute(context(0.5, 0.5, LocalizationState::kUncertain), p, &plan);
  EXPECT_EQ(0.0, plan.inject_probability);
  EXPECT_DOUBLE_EQ(0, injection.lowFitViews());
  // Half the usual fit: a dip of 1 - 0.25 / 0.35, held back for `patience` updates.
  const RecoveryContext low = context(0.5, 0.25, LocalizationState::kUncertain);
  for (int k = 1; k <= p.patience; ++k) {
    plan = RecoveryPlan();
    injection.contribute(low, p, &plan);
    EXPECT_EQ(0.0, plan.inject_probability) << k;
    EXPECT_DOUBLE_EQ(k, injection.lowFitViews());
  }
  plan = RecoveryPlan();
  injection.contribute(low, p, &plan);
  EXPECT_NEAR(1.0 - 0.25 / 0.35, plan.inject_probability, 1e-12);
  // Without free space there is nowhere to draw from.
  RecoveryContext walled = low;
  walled.has_free_space = false;
  plan = RecoveryPlan();
  injection.contribute(walled, p, &plan);
  EXPECT_EQ(0.0, plan.inject_probability);
  injection.restart();
  EXPECT_DOUBLE_EQ(0, injection.lowFitViews());
}

TEST(AugmentedMclInjection, ALostFilterDoesNotWaitAndALocalizedOneWaitsLonger) {
  RecoveryParams p;
  AugmentedMclInjection lost, localized;
  RecoveryPlan plan;
  lost.contribute(context(0.5, 0.25, LocalizationState::kLost), p, &plan);
  EXPECT_GT(plan.inject_probability, 0.0);
  for (int k = 1; k <= p.patience_localized; ++k) {
    plan = RecoveryPlan();
    localized.contribute(context(0.5, 0.25, LocalizationState::kLocalized), p, &plan);
    EXPECT_EQ(0.0, plan.inject_probability) << k;
  }
  localized.contribute(context(0.5, 0.25, LocalizationState::kLocalized), p, &plan);
  EXPECT_GT(plan.inject_probability, 0.0);
}

TEST(LostShareInjection, ACompactLostCloudSearchesAtOnce) {
  RecoveryParams p;  // lost_share 0.5
  LostShareInjection lost_share;
  RecoveryPlan plan;
  lost_share.contribute(context(0.5, 0.5, LocalizationState::kLost), p, &plan);
  EXPECT_EQ(0.5, plan.inject_probability);
  // Not while merely uncertain, nor while the cloud already searches.
  plan = RecoveryPlan();
  lost_share.contribute(context(0.5, 0.5, LocalizationState::kUncertain), p, &plan);
  EXPECT_EQ(0.0, plan.inject_probability);
  RecoveryContext searching = context(0.5, 0.5, LocalizationState::kLost);
  searching.particles = 4000;
  lost_share.contribute(searching, p, &plan);
  EXPECT_EQ(0.0, plan.inject_probability);
}

TEST(ExpansionResetting, OneScanFarBelowTheUsualFitSpreadsTheSurvivors) {
  RecoveryParams p;  // expansion_ratio 0.3
  ExpansionResetting expansion;
  RecoveryPlan plan;
  expansion.contribute(context(0.5, 0.2, LocalizationState::kLocalized), p, &plan);
  EXPECT_FALSE(plan.spread);
  expansion.contribute(context(0.5, 0.1, LocalizationState::kLocalized), p, &plan);
  EXPECT_TRUE(plan.spread);
  // No history yet: nothing to compare with.
  plan = RecoveryPlan();
  expansion.contribute(context(0.0, 0.1, LocalizationState::kLocalized), p, &plan);
  EXPECT_FALSE(plan.spread);
}

TEST(Recovery, TheAveragesStartAtTheFirstFitAndFollowAtTheirRates) {
  RecoveryParams p;  // alpha_slow 0.01, alpha_fast 0.2
  Recovery recovery;
  recovery.observe(0.5, p);
  // One scan at 0.1 after 0.5: the fast average falls to 0.42, the slow
  // one to 0.496, and 0.42 < 0.7 * 0.496 is not yet a dip.
  recovery.observe(0.1, p);
  RecoveryPlan plan = recovery.plan(LocalizationState::kLost, 500, 5000, true, p);
  EXPECT_DOUBLE_EQ(0, recovery.lowFitViews());
  EXPECT_TRUE(plan.spread);                 // 0.1 < 0.3 * 0.5
  EXPECT_EQ(0.5, plan.inject_probability);  // lost and compact: lost_share
  for (int k = 0; k < 3; ++k) recovery.observe(0.1, p);
  plan = recovery.plan(LocalizationState::kUncertain, 500, 5000, true, p);
  EXPECT_DOUBLE_EQ(1, recovery.lowFitViews());
  recovery.restart();
  recovery.observe(0.1, p);  // the first fit again
  plan = recovery.plan(LocalizationState::kUncertain, 500, 5000, true, p);
  EXPECT_FALSE(plan.spread);
  EXPECT_DOUBLE_EQ(0, recovery.lowFitViews());
}

// Updates closer together than a view (view_share.h) each count their share
// of it: the patience, the injected share, the averages' rates and the
// spread are per view, so that a view's worth of them does what one update
// a view apart does.
TEST(Recovery, UpdatesAFifthOfAViewApartCountAFifthEach) {
  RecoveryParams p;  // patience 5, alpha_slow 0.01, alpha_fast 0.2, expansion_ratio 0.3
  AugmentedMclInjection injection;
  RecoveryContext low = context(0.5, 0.25, LocalizationState::kUncertain);
  low.view = 0.2;
  RecoveryPlan plan;
  for (int k = 1; k <= 25; ++k) {  // five views: patient still
    plan = RecoveryPlan();
    injection.contribute(low, p, &plan);
    ASSERT_EQ(0.0, plan.inject_probability) << k;
  }
  EXPECT_NEAR(5.0, injection.lowFitViews(), 1e-9);
  plan = RecoveryPlan();
  injection.contribute(low, p, &plan);
  EXPECT_NEAR(0.2 * (1.0 - 0.25 / 0.35), plan.inject_probability, 1e-12);

  // The averages: five fifths move them about as far as one whole update.
  Recovery whole, fifths;
  whole.observe(0.5, p);
  fifths.observe(0.5, p);
  whole.observe(0.1, p);
  for (int k = 0; k < 5; ++k) fifths.observe(0.1, p, 0.2);
  const RecoveryPlan w = whole.plan(LocalizationState::kUncertain, 500, 5000, true, p);
  const RecoveryPlan f = fifths.plan(LocalizationState::kUncertain, 500, 5000, true, p);
  // fast: 0.5 - 0.4 * 0.2 = 0.42 in one; 0.1 + 0.4 * 0.96^5 = 0.426 in five.
  EXPECT_TRUE(w.spread);
  EXPECT_TRUE(f.spread);  // one scan far below the usual fit, either way
  EXPECT_DOUBLE_EQ(1.0, w.spread_scale);
  EXPECT_NEAR(std::sqrt(0.2), f.spread_scale, 1e-12);  // five spreads add up to one
  Recovery none;
  none.observe(0.5, p);
  for (int k = 0; k < 50; ++k) none.observe(0.1, p, 0.0);  // standing still: no new view
  EXPECT_FALSE(none.plan(LocalizationState::kUncertain, 500, 5000, true, p).inject_probability >
               0.0);
  EXPECT_DOUBLE_EQ(0.0, none.lowFitViews());
}

ParticleSet cloudAt(const Pose2& pose, std::size_t n) {
  ParticleSet s;
  s.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.setPose(i, pose);
  s.setUniformWeights();
  return s;
}

TEST(Recovery, ResamplesOnlyWhenAskedOrDegenerate) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilterParams params;
  Random random(1);
  Recovery recovery;
  ParticleSet particles = cloudAt(small_world::kTruth, 400);
  const ResampleOutcome none =
      recovery.resample(RecoveryPlan(), 400.0, params, grid, &random, &particles);
  EXPECT_FALSE(none.resampled);
  EXPECT_EQ(400u, particles.size());
}

TEST(Recovery, InjectedParticlesLieInFreeSpaceAndWeighTheKidnapPrior) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilterParams params;
  params.kld.max_particles = 1000;
  Random random(2);
  Recovery recovery;
  ParticleSet particles = cloudAt(small_world::kTruth, 400);
  RecoveryPlan plan;
  plan.inject_probability = 0.5;
  const ResampleOutcome out = recovery.resample(plan, 400.0, params, grid, &random, &particles);
  ASSERT_TRUE(out.resampled);
  EXPECT_FALSE(out.expanded);
  // floor(0.5 * 1000 + u), u in [0, 1).
  EXPECT_EQ(500u, out.injected);
  ASSERT_GT(particles.size(), out.injected);
  const std::size_t kept = particles.size() - out.injected;
  double injected_weight = 0.0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (i < kept) {
      EXPECT_EQ(small_world::kTruth.x, particles.x[i]);
    } else {
      EXPECT_TRUE(grid.isFreeAt(particles.x[i], particles.y[i])) << i;
      injected_weight += particles.weight[i];
    }
  }
  EXPECT_NEAR(params.recovery.kidnap_prior, injected_weight, 1e-12);
  EXPECT_NEAR(1.0, std::accumulate(particles.weight.begin(), particles.weight.end(), 0.0), 1e-9);
}

TEST(Recovery, SpreadingMovesTheSurvivorsByTheExpansionStd) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilterParams params;
  Random random(3);
  Recovery recovery;
  ParticleSet particles = cloudAt(small_world::kTruth, 2000);
  RecoveryPlan plan;
  plan.spread = true;
  const ResampleOutcome out = recovery.resample(plan, 2000.0, params, grid, &random, &particles);
  ASSERT_TRUE(out.resampled);
  EXPECT_TRUE(out.expanded);
  EXPECT_EQ(0u, out.injected);
  double sum = 0.0, sum2 = 0.0;
  for (const double x : particles.x) {
    sum += x - small_world::kTruth.x;
    sum2 += (x - small_world::kTruth.x) * (x - small_world::kTruth.x);
  }
  const double n = static_cast<double>(particles.size());
  EXPECT_NEAR(params.recovery.expansion_std_xy, std::sqrt(sum2 / n - (sum / n) * (sum / n)), 0.05);
}

TEST(RandomFreePose, EveryPoseIsInAFreeCell) {
  const OccupancyGrid grid = small_world::room();
  Random random(4);
  for (int k = 0; k < 2000; ++k) {
    const Pose2 p = randomFreePose(grid, &random);
    ASSERT_TRUE(grid.isFreeAt(p.x, p.y)) << p.x << ", " << p.y;
    ASSERT_GE(p.yaw, -M_PI);
    ASSERT_LT(p.yaw, M_PI);
  }
}

}  // namespace
}  // namespace pf

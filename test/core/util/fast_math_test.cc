#include "pf_localization/core/util/fast_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "pf_localization/core/filter/weighting.h"
#include "pf_localization/core/util/random.h"

namespace {

TEST(FastMath, SinCosAtKnownAngles) {
  const std::vector<double> a = {0.0, M_PI / 6, M_PI / 4, M_PI / 2, 2.0, M_PI, -M_PI, -2.5, 7.0};
  std::vector<double> s(a.size()), c(a.size());
  pf::sinCos(a.data(), a.size(), s.data(), c.data());
  EXPECT_EQ(s[0], 0.0);
  EXPECT_EQ(c[0], 1.0);
  EXPECT_NEAR(s[1], 0.5, 2.3e-16);
  EXPECT_NEAR(c[1], 0.8660254037844386, 2.3e-16);
  EXPECT_NEAR(s[2], 0.7071067811865476, 2.3e-16);
  EXPECT_NEAR(c[3], 6.123233995736766e-17, 2.3e-16);
  EXPECT_NEAR(s[4], 0.9092974268256817, 2.3e-16);
  EXPECT_NEAR(c[4], -0.4161468365471424, 2.3e-16);
  EXPECT_NEAR(c[5], -1.0, 2.3e-16);
  EXPECT_NEAR(c[6], -1.0, 2.3e-16);
  EXPECT_NEAR(s[7], -0.5984721441039564, 2.3e-16);
  EXPECT_NEAR(c[8], 0.7539022543433046, 2.3e-16);
}

TEST(FastMath, SinCosMatchesTheCLibraryOverManyTurns) {
  pf::Random random(1);
  std::vector<double> a(100000), s(a.size()), c(a.size());
  for (double& v : a) v = random.uniform(-50.0, 50.0);
  pf::sinCos(a.data(), a.size(), s.data(), c.data());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max({worst, std::fabs(s[i] - std::sin(a[i])), std::fabs(c[i] - std::cos(a[i]))});
  }
  EXPECT_LT(worst, 4e-16);
}

TEST(FastMath, SinCosFallsBackBeyondItsRange) {
  const std::vector<double> a = {1e7, -3e9, std::numeric_limits<double>::infinity(),
                                 std::numeric_limits<double>::quiet_NaN()};
  std::vector<double> s(a.size()), c(a.size());
  pf::sinCos(a.data(), a.size(), s.data(), c.data());
  EXPECT_EQ(s[0], std::sin(1e7));
  EXPECT_EQ(c[1], std::cos(-3e9));
  EXPECT_TRUE(std::isnan(s[2]));
  EXPECT_TRUE(std::isnan(c[3]));
}

TEST(FastMath, ExpWithinOneUlpAndAtItsEdges) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> x = {0.0,    1.0,    -1.0,   -0.5,        2.302585092994046,
                           -700.0, -709.0, -745.0, -746.0,      709.7,
                           710.0,  -inf,   inf,    std::nan("")};
  std::vector<double> e(x.size());
  pf::exps(x.data(), x.size(), e.data());
  EXPECT_EQ(e[0], 1.0);
  EXPECT_NEAR(e[1], 2.718281828459045, 4.5e-16);
  EXPECT_NEAR(e[2], 0.36787944117144233, 1e-16);
  EXPECT_NEAR(e[3], 0.6065306597126334, 1.2e-16);
  EXPECT_NEAR(e[4], 10.0, 2e-15);
  EXPECT_NEAR(e[5] / 9.85967654375977e-305, 1.0, 4e-16);
  EXPECT_NEAR(e[6] / 1.2167807506234229e-308, 1.0, 1e-12);  // subnormal
  EXPECT_EQ(e[7], 4.9406564584124654e-324);
  EXPECT_EQ(e[8], 0.0);
  EXPECT_NEAR(e[9] / 1.6549840276802644e+308, 1.0, 4e-16);
  EXPECT_EQ(e[10], inf);
  EXPECT_EQ(e[11], 0.0);
  EXPECT_EQ(e[12], inf);
  EXPECT_TRUE(std::isnan(e[13]));
  // In place, over the range the weighting uses.
  pf::Random random(2);
  std::vector<double> y(50000);
  for (double& v : y) v = random.uniform(-40.0, 3.0);
  const std::vector<double> copy = y;
  pf::exps(y.data(), y.size(), y.data());
  double worst = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    worst = std::max(worst, std::fabs(y[i] / std::exp(copy[i]) - 1.0));
  }
  EXPECT_LT(worst, 2.3e-16);
}

// Literal values for one small case of the weighting step.
TEST(Weighting, NormalisesThePosteriorAndAveragesTheBeamFit) {
  std::vector<double> weights = {0.25, 0.25, 0.25, 0.25};
  const std::vector<double> ll = {-1.0, -2.0, -3.0, std::log(0.5) - 1.0};
  pf::WeightingScratch scratch;
  EXPECT_EQ(pf::applyLikelihood(ll, 0.0, &weights, &scratch), 1.0);
  const double t = 1.0 + std::exp(-1.0) + std::exp(-2.0) + 0.5;
  EXPECT_NEAR(weights[0], 1.0 / t, 1e-15);
  EXPECT_NEAR(weights[1], std::exp(-1.0) / t, 1e-15);
  EXPECT_NEAR(weights[3], 0.5 / t, 1e-15);
  // The geometric mean over 2 beams, averaged with the posterior.
  double expected = 0.0;
  for (int i = 0; i < 4; ++i) expected += weights[i] * std::exp(ll[i] / 2.0);
  EXPECT_NEAR(pf::meanBeamLikelihood(weights, ll, 2.0), expected, 1e-15);
  // A weighted prior: the posterior is prior * likelihood, normalised.
  std::vector<double> w2 = {0.5, 0.25, 0.125, 0.125};
  pf::applyLikelihood({0.0, 0.0, 0.0, std::log(2.0)}, 0.0, &w2, &scratch);
  EXPECT_NEAR(w2[0], 0.5 / 1.125, 1e-15);
  EXPECT_NEAR(w2[3], 0.25 / 1.125, 1e-15);
}

TEST(Weighting, TempersEvidenceTooStrongForTheCloud) {
  std::vector<double> weights(100, 0.01);
  std::vector<double> ll(100, -100.0);
  ll[0] = 0.0;  // one particle alone explains the scan
  pf::WeightingScratch scratch;
  const double beta = pf::applyLikelihood(ll, 0.1, &weights, &scratch);
  EXPECT_GT(beta, 0.0);
  EXPECT_LT(beta, 0.1);
  double sum = 0.0, sum_sq = 0.0;
  for (double w : weights) {
    sum += w;
    sum_sq += w * w;
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_GE(1.0 / sum_sq, 10.0 * (1.0 - 1e-4));  // kept 10 % of the 100 effective particles
}

}  // namespace

#include "pf_localization/core/sensor/beam_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "support/rooms.h"

namespace pf {
namespace {

// The tests' wall: wallGrid(8), 10 x 5 cells of 0.1 m, column 8 (x in
// [0.8, 0.9)) occupied.
using test::wallGrid;

// z_hit 0.8, z_short 0.1, z_max 0.05, z_rand 0.05, sigma_hit 0.2 m,
// lambda_short 0.5 /m, range_max 4 m, untempered.
LikelihoodFieldModelParams shared() {
  LikelihoodFieldModelParams p;
  p.z_hit = 0.8;
  p.z_rand = 0.05;
  p.sigma_hit = 0.2;
  p.likelihood_exponent = 1.0;
  return p;
}

BeamModelParams beamTerms() {
  BeamModelParams p;
  p.z_short = 0.1;
  p.z_max = 0.05;
  p.lambda_short = 0.5;
  return p;
}

// Beams at 0 and pi/2 rad with the given ranges, range_max 4 m.
LaserScan twoBeams(float ahead, float left) {
  LaserScan scan;
  scan.ranges = {ahead, left};
  scan.angle_min = 0.0;
  scan.angle_increment = M_PI / 2;
  scan.range_min = 0.05;
  scan.range_max = 4.0;
  return scan;
}

// z_hit N(0; 0, 0.2) = 0.8 / (0.2 sqrt(2 pi)) = 1.595769; z_rand / range_max = 0.0125.
//   a beam that ends where the map says:       p = 1.595769 + 0.0125          = 1.608269
//   measured 0.56 m where the map says 0.55 m: p = 1.595769 exp(-0.5 * 0.01^2 / 0.2^2)
//                                                = 1.593776, + 0.0125          = 1.606276
//   measured 0.2 m where the map says 4 m:     p = 0.8 N(-3.8; 0, 0.2) (~1e-78)
//                     + 0.1 * 0.5 exp(-0.5 * 0.2) + 0.0125                    = 0.057742
//   measured 0.56 m where the map says 0.75 m: p = 0.8 N(-0.19; 0, 0.2)
//     = 1.016236, + 0.1 * 0.5 exp(-0.5 * 0.56) = 0.037789, + 0.0125            = 1.066525
constexpr double kLogExact = 0.47515852093562067;
constexpr double kLogLongBy1cm = 0.4739182423768205;
constexpr double kLogShortOf4 = -2.85177270309359;
constexpr double kLogShortOf075 = 0.06440608700875515;

TEST(BeamModel, BeamProbabilityFormula) {
  const BeamModel model(wallGrid(8), shared(), beamTerms());
  EXPECT_NEAR(std::exp(kLogExact), model.beamProbability(0.55, 0.55, 4.0), 1e-12);
  EXPECT_NEAR(std::exp(kLogShortOf4), model.beamProbability(0.2, 4.0, 4.0), 1e-12);
  EXPECT_NEAR(std::exp(kLogLongBy1cm), model.beamProbability(0.56, 0.55, 4.0), 1e-12);
  EXPECT_NEAR(std::exp(kLogShortOf075), model.beamProbability(0.56, 0.75, 4.0), 1e-12);
  // Longer than expected: no short term, only the hit's tail and z_rand.
  EXPECT_NEAR(0.0125, model.beamProbability(3.0, 0.5, 4.0), 1e-12);
  // A max-range reading gets z_max instead of z_rand.
  EXPECT_NEAR(0.05 + 0.8 * std::exp(-0.5) / (0.2 * std::sqrt(2.0 * M_PI)),
              model.beamProbability(4.0, 3.8, 4.0), 1e-12);
}

TEST(BeamModel, WeightOfAKnownScanOnALiteralWall) {
  const BeamModel model(wallGrid(8), shared(), beamTerms());
  // 0.56 m, not 0.55: a reading exactly at the expected range is on the
  // edge of the short term (which applies below it), and float rounding
  // would decide the side.
  const PreparedScan scan = model.prepare(twoBeams(0.56f, 0.2f));
  ASSERT_EQ(2u, scan.size());
  // From (0.25, 0.25) facing +x the map says 0.55 m ahead (the wall is
  // entered at x = 0.8) and 4 m to the left (the ray leaves the 0.5 m high
  // map): log 1.606276 + log 0.057742.
  EXPECT_NEAR(kLogLongBy1cm + kLogShortOf4, model.logLikelihood(scan, {0.25, 0.25, 0.0}), 1e-6);
  // 0.2 m further back the map says 0.75 m ahead: the 0.56 m reading is short.
  EXPECT_NEAR(kLogShortOf075 + kLogShortOf4, model.logLikelihood(scan, {0.05, 0.25, 0.0}), 1e-6);
  // logLikelihoods gives each particle the same, and counts every beam.
  ParticleSet particles;
  particles.resize(2);
  particles.setPose(0, {0.25, 0.25, 0.0});
  particles.setPose(1, {0.05, 0.25, 0.0});
  std::vector<double> ll;
  EXPECT_EQ(2u, model.logLikelihoods(scan, particles, &ll));
  ASSERT_EQ(2u, ll.size());
  EXPECT_DOUBLE_EQ(model.logLikelihood(scan, {0.25, 0.25, 0.0}), ll[0]);
  EXPECT_DOUBLE_EQ(model.logLikelihood(scan, {0.05, 0.25, 0.0}), ll[1]);
  EXPECT_GT(ll[0], ll[1]);
}

TEST(BeamModel, TheSensorMountIsHonoured) {
  const BeamModel model(wallGrid(8), shared(), beamTerms());
  LaserScan scan = twoBeams(0.56f, 0.2f);
  // The laser 0.2 m ahead of the base: the base at x = 0.05 sees what a
  // laser at x = 0.25 sees.
  scan.sensor_pose = {0.2, 0.0, 0.0};
  EXPECT_NEAR(kLogLongBy1cm + kLogShortOf4,
              model.logLikelihood(model.prepare(scan), {0.05, 0.25, 0.0}), 1e-6);
}

TEST(BeamModel, RefusesBadTerms) {
  BeamModelParams p = beamTerms();
  p.lambda_short = 0.0;
  EXPECT_THROW(BeamModel(wallGrid(8), shared(), p), std::invalid_argument);
  p = beamTerms();
  p.z_short = -1.0;
  EXPECT_THROW(BeamModel(wallGrid(8), shared(), p), std::invalid_argument);
  p = beamTerms();
  p.z_max = NAN;
  EXPECT_THROW(BeamModel(wallGrid(8), shared(), p), std::invalid_argument);
}

}  // namespace
}  // namespace pf

// Beam skipping in the likelihood field model (amcl's likelihood_field_prob
// with do_beamskip).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "pf_localization/core/map/distance_field_ray_caster.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/util/random.h"
#include "support/rooms.h"

namespace pf {
namespace {

// A 4 m x 4 m room of 0.1 m cells, walls on the border cells.
OccupancyGrid room() { return test::room(4.0, 4.0, 0.1); }

constexpr int kBeams = 30;

// 30 beams every 12 deg from -174 deg, seen from (2, 2, 0): every beam ends
// 2 cm inside the mapped walls, except the 10 within 60 deg of +x (-54 ...
// 54 deg, a third of them), which end 1.32 m away on an unmapped round
// obstacle (a crowd): at least 0.6 m from every mapped wall's cell centre
// (straight ahead in cell column 33, where the wall is column 39), so a
// particle 0.1 m further in +x places that end point 0.5 m from it and one
// 0.2 m further 0.4 m from it, inside beam_skip_distance.
LaserScan scanWithUnmappedObstacle() {
  const OccupancyGrid map = room();
  const DistanceFieldRayCaster caster(map);
  LaserScan scan;
  scan.angle_min = -M_PI + M_PI / 30;
  scan.angle_increment = 2 * M_PI / kBeams;
  scan.range_min = 0.05;
  scan.range_max = 5.0;
  for (int i = 0; i < kBeams; ++i) {
    const double a = scan.angle_min + i * scan.angle_increment;
    const bool unmapped = std::fabs(a) < M_PI / 3;
    scan.ranges.push_back(
        static_cast<float>(unmapped ? 1.32 : caster.cast(2.0, 2.0, a, 5.0) + 0.02));
  }
  return scan;
}

// The true pose first, then 199 particles around it (0.1 m, 0.05 rad).
ParticleSet cloud() {
  Random random(3);
  ParticleSet set;
  set.resize(200);
  set.setPose(0, {2.0, 2.0, 0.0});
  for (std::size_t i = 1; i < set.size(); ++i) {
    set.setPose(i, {2.0 + random.gaussian(0.1), 2.0 + random.gaussian(0.1), random.gaussian(0.05)});
  }
  set.setUniformWeights();
  return set;
}

LikelihoodFieldModelParams params(bool beam_skip) {
  LikelihoodFieldModelParams p;
  p.max_beams = kBeams;
  p.likelihood_exponent = 1.0;
  p.beam_skip = beam_skip;  // amcl's defaults: 0.5 m, 0.3, 0.9
  return p;
}

std::size_t best(const std::vector<double>& ll) {
  return static_cast<std::size_t>(std::max_element(ll.begin(), ll.end()) - ll.begin());
}

TEST(BeamSkip, TheBeamsOnAnUnmappedObstacleAreSkippedAndTheTruePoseWins) {
  const ParticleSet particles = cloud();
  const LikelihoodFieldModel skipping(room(), params(true));
  const PreparedScan scan = skipping.prepare(scanWithUnmappedObstacle());
  ASSERT_EQ(static_cast<std::size_t>(kBeams), scan.size());
  std::vector<double> ll;
  // The 10 beams on the unmapped wall end 0.5 m or more from the mapped
  // one for the particles less than 0.15 m further in +x, far more than 70 %
  // of them: too few agree, they are skipped. The 20 others end on the
  // walls for most particles.
  EXPECT_EQ(20u, skipping.logLikelihoods(scan, particles, &ll));
  for (std::size_t i = 1; i < particles.size(); ++i) {
    EXPECT_GE(ll[0], ll[i]) << "particle " << i << " beats the true pose";
  }
  // What the skipped beams would have done: pulled the best weight towards
  // the mapped wall behind the obstacle (+x), away from the true pose. From
  // 0.6 m to 0.4 m a beam gains log((1.9 e^-2 + 0.01) / (1.9 e^-4.5 + 0.01))
  // = 2.1 nats; the beams behind, on the mapped wall at -x, lose less.
  const LikelihoodFieldModel plain(room(), params(false));
  EXPECT_EQ(static_cast<std::size_t>(kBeams), plain.logLikelihoods(scan, particles, &ll));
  EXPECT_GT(particles.x[best(ll)], 2.05);
}

TEST(BeamSkip, NothingIsSkippedWhenTooManyBeamsWouldBe) {
  // A third of the beams would be skipped: at an error threshold of 0.3 that
  // is too many, the cloud is more likely wrong than the map, all count.
  LikelihoodFieldModelParams p = params(true);
  p.beam_skip_error_threshold = 0.3;
  const LikelihoodFieldModel model(room(), p);
  const PreparedScan scan = model.prepare(scanWithUnmappedObstacle());
  std::vector<double> ll;
  EXPECT_EQ(static_cast<std::size_t>(kBeams), model.logLikelihoods(scan, cloud(), &ll));
  // And the scores are then those of the model without skipping.
  std::vector<double> plain_ll;
  LikelihoodFieldModel(room(), params(false)).logLikelihoods(scan, cloud(), &plain_ll);
  EXPECT_EQ(plain_ll, ll);
}

TEST(BeamSkip, OnePoseIsScoredOnEveryBeam) {
  const LikelihoodFieldModel skipping(room(), params(true));
  const LikelihoodFieldModel plain(room(), params(false));
  const PreparedScan scan = skipping.prepare(scanWithUnmappedObstacle());
  EXPECT_EQ(plain.logLikelihood(scan, {2.0, 2.0, 0.0}),
            skipping.logLikelihood(scan, {2.0, 2.0, 0.0}));
}

TEST(BeamSkip, TheModelRefusesBadSkipParameters) {
  LikelihoodFieldModelParams p = params(true);
  p.beam_skip_threshold = 1.5;
  try {
    LikelihoodFieldModel model(room(), p);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ("invalid parameter beam_skip_threshold = 1.5: must be in [0, 1]", e.what());
  }
  p = params(true);
  p.beam_skip_distance = 0.0;
  EXPECT_THROW(LikelihoodFieldModel(room(), p), std::invalid_argument);
  // Unchecked, as unused, while skipping is off.
  p.beam_skip = false;
  EXPECT_NO_THROW(LikelihoodFieldModel(room(), p));
}

}  // namespace
}  // namespace pf

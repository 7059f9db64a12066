#include "pf_localization/core/sensor/likelihood_field_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/util/random.h"
#include "support/rooms.h"

namespace pf {
namespace {

// wallGrid(column, origin): 10 x 5 cells of 0.1 m (1 m x 0.5 m); the cells of
// column `column` are occupied, everything else free.
using test::wallGrid;

// Per-beam values are tabulated as float.
constexpr double kTol = 1e-5;

// p = z_hit N(d; 0, 0.2) + z_rand / range_max with z_hit 0.9, z_rand 0.1 and
// range_max 4 m; z_hit N(0; 0, 0.2) = 0.9 / (0.2 sqrt(2 pi)) = 1.795240.
//   d = 0:   log(1.795240 + 0.025)                     =  0.598969
//   d = 0.2: log(1.795240 exp(-0.5) + 0.025)            =  0.107839
//   d = 0.3: log(1.795240 exp(-1.125) + 0.025)          = -0.497861
//   d = 0.5: log(1.795240 exp(-3.125) + 0.025)          = -2.264544
//   d = 0.6: log(1.795240 exp(-4.5) + 0.025)            = -3.102353
//   d = 0.8: log(1.795240 exp(-8) + 0.025)              = -3.665076
constexpr double kLogP0 = 0.5989685043574534;
constexpr double kLogP02 = 0.1078388762859554;
constexpr double kLogP03 = -0.4978613896214299;
constexpr double kLogP05 = -2.264544381335515;
constexpr double kLogP06 = -3.1023531864294274;
constexpr double kLogP08 = -3.665075586938184;

LikelihoodFieldModelParams params(double max_distance = 2.0) {
  LikelihoodFieldModelParams p;
  p.z_hit = 0.9;
  p.z_rand = 0.1;
  p.sigma_hit = 0.2;
  p.max_distance = max_distance;
  p.max_beams = 60;
  // Untempered, so that the expected values are the plain sums of log p.
  p.likelihood_exponent = 1.0;
  return p;
}

// Beams at 0, pi/2, pi, ... rad with the given ranges.
LaserScan quarterScan(std::vector<float> ranges, double range_max = 4.0) {
  LaserScan scan;
  scan.ranges = std::move(ranges);
  scan.angle_min = 0.0;
  scan.angle_increment = M_PI / 2;
  scan.range_min = 0.05;
  scan.range_max = range_max;
  return scan;
}

TEST(LikelihoodFieldModel, BeamLogLikelihoodFormula) {
  LikelihoodFieldModelParams p;
  p.z_hit = 0.8;
  p.z_rand = 0.2;
  p.sigma_hit = 0.5;
  const LikelihoodFieldModel model(wallGrid(8), p);
  // 0.8 exp(-0.5 * 0.3^2 / 0.5^2) / (0.5 sqrt(2 pi)) = 0.8 * 0.835270 / 1.253314
  // = 0.533159, plus 0.2 / 4 = 0.05: log(0.583159) = -0.539295.
  EXPECT_NEAR(-0.5392947772809207, model.beamLogLikelihood(0.3, 4.0), 1e-12);
  // Far away only the random component is left: log(0.2 / 4).
  EXPECT_NEAR(std::log(0.05), model.beamLogLikelihood(100.0, 4.0), 1e-12);
  // A longer range_max spreads z_rand thinner.
  EXPECT_NEAR(std::log(0.025), model.beamLogLikelihood(100.0, 8.0), 1e-12);

  const LikelihoodFieldModel m2(wallGrid(8), params());
  EXPECT_NEAR(kLogP0, m2.beamLogLikelihood(0.0, 4.0), 1e-12);
  EXPECT_NEAR(kLogP06, m2.beamLogLikelihood(0.6, 4.0), 1e-12);
}

TEST(LikelihoodFieldModel, PrepareDropsBadBeamsAndPlacesEndPoints) {
  const LikelihoodFieldModel model(wallGrid(8), params());
  const PreparedScan scan = model.prepare(quarterScan({1.0f, NAN, 2.0f, 0.0f}));
  EXPECT_EQ(2, scan.dropped);
  EXPECT_EQ(4.0, scan.range_max);
  ASSERT_EQ(2u, scan.size());
  EXPECT_NEAR(1.0, scan.x[0], 1e-6);  // ahead
  EXPECT_NEAR(0.0, scan.y[0], 1e-6);
  EXPECT_NEAR(-2.0, scan.x[1], 1e-6);  // behind
  EXPECT_NEAR(0.0, scan.y[1], 1e-6);
}

TEST(LikelihoodFieldModel, PrepareHonoursTheRangeOverrides) {
  LikelihoodFieldModelParams p = params();
  p.range_max = 1.5;  // tighter than the scan's 4 m: drops the 2 m and 3 m beams
  p.range_min = 0.5;  // drops the 0.2 m beam
  const LikelihoodFieldModel model(wallGrid(8), p);
  const PreparedScan scan = model.prepare(quarterScan({0.2f, 1.0f, 2.0f, 3.0f}));
  EXPECT_EQ(3, scan.dropped);
  EXPECT_EQ(1.5, scan.range_max);  // and z_rand is spread over 1.5 m
  ASSERT_EQ(1u, scan.size());
  EXPECT_NEAR(0.0, scan.x[0], 1e-6);
  EXPECT_NEAR(1.0, scan.y[0], 1e-6);
}

TEST(LikelihoodFieldModel, HitAndMissOnALiteralWall) {
  // The wall is column 8, x in [0.8, 0.9).
  const LikelihoodFieldModel model(wallGrid(8), params());
  const PreparedScan scan = model.prepare(quarterScan({0.6f, 0.1f}));
  ASSERT_EQ(2u, scan.size());
  // From (0.25, 0.25) facing +x the beam ahead ends at x = 0.85, in the wall
  // (d = 0); the beam to the left ends at (0.25, 0.35), cell (2, 3), six
  // cells from the wall (d = 0.6).
  EXPECT_NEAR(kLogP0 + kLogP06, model.logLikelihood(scan, {0.25, 0.25, 0.0}), kTol);
  // 0.2 m further back, the first beam stops two cells short of the wall
  // (d = 0.2) and the second ends in cell (0, 3), eight cells away (d = 0.8).
  EXPECT_NEAR(kLogP02 + kLogP08, model.logLikelihood(scan, {0.05, 0.25, 0.0}), kTol);
  // The hit scores better than the miss.
  EXPECT_GT(model.logLikelihood(scan, {0.25, 0.25, 0.0}),
            model.logLikelihood(scan, {0.05, 0.25, 0.0}));
  // Facing +y from (0.35, 0.05): the first beam goes up to (0.35, 0.65) and
  // leaves the 0.5 m high map (d = max_distance = 2, log(0.025 + ~0)); the
  // second goes left to (0.25, 0.05), d = 0.6.
  EXPECT_NEAR(std::log(0.025) + kLogP06, model.logLikelihood(scan, {0.35, 0.05, M_PI / 2}), kTol);
}

TEST(LikelihoodFieldModel, LaserMountedBackwards) {
  // Wall in column 0, x in [0, 0.1). The robot at (0.45, 0.25) faces +x; its
  // laser sits 0.1 m behind its centre, looking backwards.
  const LikelihoodFieldModel model(wallGrid(0), params());
  LaserScan raw = quarterScan({0.3f, 0.1f});
  raw.sensor_pose = {-0.1, 0.0, M_PI};
  const PreparedScan scan = model.prepare(raw);
  ASSERT_EQ(2u, scan.size());
  // The laser's beam ahead (0.3, 0) is (-0.1 - 0.3, 0) on the robot; its beam
  // to the left (0, 0.1) is the robot's right: (-0.1, -0.1).
  EXPECT_NEAR(-0.4, scan.x[0], 1e-6);
  EXPECT_NEAR(0.0, scan.y[0], 1e-6);
  EXPECT_NEAR(-0.1, scan.x[1], 1e-6);
  EXPECT_NEAR(-0.1, scan.y[1], 1e-6);
  // In the world: (0.05, 0.25) in the wall (d = 0) and (0.35, 0.15), cell
  // (3, 1), three cells from it (d = 0.3).
  EXPECT_NEAR(kLogP0 + kLogP03, model.logLikelihood(scan, {0.45, 0.25, 0.0}), kTol);
  // A robot turned around, at (0.35, 0.25) facing -x, has its laser at
  // (0.45, 0.25) looking +x: the beams end at (0.75, 0.25) (d = 0.7) and
  // (0.45, 0.35) (d = 0.4) - nowhere near the wall.
  EXPECT_NEAR(model.beamLogLikelihood(0.7, 4.0) + model.beamLogLikelihood(0.4, 4.0),
              model.logLikelihood(scan, {0.35, 0.25, M_PI}), kTol);
}

TEST(LikelihoodFieldModel, EndPointsOutsideTheMapScoreMaxDistance) {
  // Capped at 0.5 m so that the cap is visible inside the map too.
  const LikelihoodFieldModel model(wallGrid(8), params(0.5));
  auto score = [&](float range, double bearing, const Pose2& pose) {
    LaserScan raw = quarterScan({range});
    raw.angle_min = bearing;
    return model.logLikelihood(model.prepare(raw), pose);
  };
  const Pose2 pose{0.25, 0.25, 0.0};
  EXPECT_NEAR(kLogP05, score(1.0f, -M_PI / 2, pose), kTol);         // (0.25, -0.75): below
  EXPECT_NEAR(kLogP05, score(0.5f, M_PI, pose), kTol);              // (-0.25, 0.25): left of it
  EXPECT_NEAR(kLogP05, score(0.85f, 0.0, pose), kTol);              // (1.1, 0.25): beyond the wall
  EXPECT_NEAR(kLogP05, score(3.9f, M_PI / 4, pose), kTol);          // far up and right
  EXPECT_NEAR(kLogP05, score(0.15f, 0.0, {-1e5, 1e5, 0.0}), kTol);  // far away
  // Inside the map the same cap applies: (0.05, 0.25) is 0.8 m from the wall.
  EXPECT_NEAR(kLogP05, score(0.2f, M_PI, pose), kTol);
  EXPECT_NEAR(kLogP0, score(0.6f, 0.0, pose), kTol);  // and the wall still scores d = 0
}

TEST(LikelihoodFieldModel, RangeMaxChangesAreNotServedFromAStaleTable) {
  const LikelihoodFieldModel model(wallGrid(8), params());
  const PreparedScan short_scan = model.prepare(quarterScan({0.6f, 0.1f}, 4.0));
  const PreparedScan long_scan = model.prepare(quarterScan({0.6f, 0.1f}, 8.0));
  const Pose2 pose{0.25, 0.25, 0.0};
  const double expected_long =
      model.beamLogLikelihood(0.0, 8.0) + model.beamLogLikelihood(0.6, 8.0);  // -2.836183
  EXPECT_NEAR(kLogP0 + kLogP06, model.logLikelihood(short_scan, pose), kTol);
  EXPECT_NEAR(-2.8361831871950933, model.logLikelihood(long_scan, pose), kTol);
  EXPECT_NEAR(expected_long, model.logLikelihood(long_scan, pose), kTol);
  EXPECT_NEAR(kLogP0 + kLogP06, model.logLikelihood(short_scan, pose), kTol);
}

TEST(LikelihoodFieldModel, EveryCellScoresItsOwnDistanceOnALargeMap) {
  // 200 x 200 cells of 0.1 m with one occupied cell in a corner and no cap
  // inside the map: 13 648 distinct distances, so that the table's memo of
  // exp and log (16 384 slots, direct-mapped) evicts and recomputes entries.
  // A Gaussian without z_rand, so that near distances give distinct values.
  std::vector<int8_t> data(200 * 200, 0);
  data[0] = 100;
  LikelihoodFieldModelParams p = params(100.0);
  p.z_rand = 0.0;
  p.sigma_hit = 5.0;
  const LikelihoodFieldModel model(OccupancyGrid(200, 200, 0.1, {}, data), p);
  const DistanceField& field = model.field();
  // One beam of 1 m along +x, from 1 m left of each cell's centre.
  const PreparedScan scan = model.prepare(quarterScan({1.0f}));
  ASSERT_EQ(1u, scan.size());
  for (int y = 0; y < 200; y += 3) {
    for (int x = 0; x < 200; ++x) {
      const float expected =
          static_cast<float>(model.beamLogLikelihood(field.distance(y * 200 + x), scan.range_max));
      const double got = model.logLikelihood(scan, {(x + 0.5) * 0.1 - 1.0, (y + 0.5) * 0.1, 0.0});
      ASSERT_EQ(expected, static_cast<float>(got)) << "cell (" << x << ", " << y << ")";
    }
  }
}

TEST(LikelihoodFieldModel, RotatedMapOrigin) {
  // The same cells, but the map's x axis points along world +y and its
  // corner is at (2, 1): a pose p of the unrotated map is origin (+) p here.
  const Pose2 origin{2.0, 1.0, M_PI / 2};
  const LikelihoodFieldModel plain(wallGrid(8), params());
  const LikelihoodFieldModel rotated(wallGrid(8, origin), params());
  const PreparedScan scan = rotated.prepare(quarterScan({0.6f, 0.1f, 0.3f, 0.2f}));
  // The literal case: (0.25, 0.25, 0) becomes (1.75, 1.25, pi/2).
  const PreparedScan two = rotated.prepare(quarterScan({0.6f, 0.1f}));
  EXPECT_NEAR(kLogP0 + kLogP06, rotated.logLikelihood(two, {1.75, 1.25, M_PI / 2}), kTol);
  // Ahead of (0.25, 0.25, 0) in the unrotated world is outside the rotated map.
  EXPECT_NEAR(std::log(0.025) + std::log(0.025), rotated.logLikelihood(two, {0.25, 0.25, 0.0}),
              1e-4);
  const Pose2 poses[] = {{0.25, 0.25, 0.0}, {0.55, 0.15, 0.3}, {0.35, 0.45, -2.0}};
  for (const Pose2& p : poses) {
    EXPECT_NEAR(plain.logLikelihood(scan, p), rotated.logLikelihood(scan, compose(origin, p)),
                kTol);
  }
}

// Scores a cloud on the model with `layout`'s tables, as below.
void expectCloudMatchesPerPoseAndBruteForce(LikelihoodFieldModel::TableLayout layout);

TEST(LikelihoodFieldModel, ParticleSetMatchesPerPoseAndBruteForce) {
  expectCloudMatchesPerPoseAndBruteForce(LikelihoodFieldModel::TableLayout::kPerCell);
}

TEST(LikelihoodFieldModel, TablesByClassScoreAsTablesByCell) {
  expectCloudMatchesPerPoseAndBruteForce(LikelihoodFieldModel::TableLayout::kPerClass);
  // The same bits both ways, on and off the map.
  const OccupancyGrid grid = test::wallGrid(8);
  const LikelihoodFieldModel by_cell(grid, params(), LikelihoodFieldModel::TableLayout::kPerCell);
  const LikelihoodFieldModel by_class(grid, params(), LikelihoodFieldModel::TableLayout::kPerClass);
  ParticleSet set;
  set.resize(203);
  Random random(5);
  for (std::size_t i = 0; i < set.size(); ++i) {
    set.setPose(i, {random.uniform(-0.5, 1.5), random.uniform(-0.5, 1.0), random.uniform(-3, 3)});
  }
  const LaserScan scan = quarterScan({0.3f, 0.2f, 0.4f, 0.25f});
  std::vector<double> a, b;
  by_cell.logLikelihoods(by_cell.prepare(scan), set, &a);
  by_class.logLikelihoods(by_class.prepare(scan), set, &b);
  EXPECT_EQ(a, b);
}

void expectCloudMatchesPerPoseAndBruteForce(LikelihoodFieldModel::TableLayout layout) {
  // A 3 m x 2 m room of 0.05 m cells with walls on its border and a pillar.
  const int w = 60, h = 40;
  std::vector<int8_t> data(w * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool border = x == 0 || y == 0 || x == w - 1 || y == h - 1;
      const bool pillar = x >= 30 && x < 36 && y >= 10 && y < 14;
      if (border || pillar) data[y * w + x] = 100;
      if (x >= 40 && x < 45 && y >= 30 && y < 35) data[y * w + x] = -1;
    }
  }
  const OccupancyGrid grid(w, h, 0.05, {-0.5, -0.3, 0.2}, data);
  LikelihoodFieldModelParams p = params(1.0);
  p.max_beams = 30;
  const LikelihoodFieldModel model(grid, p, layout);

  LaserScan raw;
  raw.angle_min = -2.0;
  raw.angle_increment = 0.1;
  raw.range_min = 0.1;
  raw.range_max = 5.0;
  raw.sensor_pose = {0.12, -0.03, 0.05};
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> range(0.05f, 5.5f);  // some out of limits
  for (int i = 0; i < 41; ++i) raw.ranges.push_back(range(rng));
  const PreparedScan scan = model.prepare(raw);
  ASSERT_GT(scan.size(), 20u);

  ParticleSet particles;
  std::uniform_real_distribution<double> coord(-1.0, 3.0), angle(-M_PI, M_PI);
  particles.resize(50);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    particles.setPose(i, {coord(rng), coord(rng), angle(rng)});
  }
  std::vector<double> all;
  model.logLikelihoods(scan, particles, &all);
  ASSERT_EQ(particles.size(), all.size());
  for (std::size_t i = 0; i < particles.size(); ++i) {
    // The same bits: the cloud is scored eight particles at a time where the
    // processor has AVX2 (the last two one by one), a single pose one by one.
    EXPECT_EQ(model.logLikelihood(scan, particles.pose(i)), all[i]) << "particle " << i;
    // An independent reference: every end point placed in double precision
    // and looked up in the distance field.
    double expected = 0.0;
    for (std::size_t b = 0; b < scan.size(); ++b) {
      const Pose2 end = compose(particles.pose(i), {scan.x[b], scan.y[b], 0.0});
      expected += model.beamLogLikelihood(model.field().distanceAt(end.x, end.y), scan.range_max);
    }
    EXPECT_NEAR(expected, all[i], 1e-4) << "particle " << i;
  }

  // A block of eight far off the map, at infinity and NaN (every end point
  // in the border: the floor score), then one more on the map.
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Pose2> odd = {{-40.0, 1.0, 0.3}, {1e7, -1e7, 1.0}, {inf, 0.5, 0.0},
                                  {0.5, -inf, 2.0},  {nan, 0.5, 0.0},  {0.5, 0.5, nan},
                                  {1.0, nan, -1.0},  {3.0, 2.0, 1e9},  {1.2, 0.4, -0.7}};
  particles.resize(odd.size());
  for (std::size_t i = 0; i < odd.size(); ++i) particles.setPose(i, odd[i]);
  model.logLikelihoods(scan, particles, &all);
  const double floor_score =
      static_cast<double>(scan.size()) *
      static_cast<float>(model.beamLogLikelihood(model.field().maxDistance(), scan.range_max));
  for (std::size_t i = 0; i < odd.size(); ++i) {
    EXPECT_EQ(model.logLikelihood(scan, odd[i]), all[i]) << "particle " << i;
  }
  for (std::size_t i : {0, 1, 2, 3, 4, 5, 6}) {
    EXPECT_NEAR(floor_score, all[i], 1e-3) << "particle " << i;
  }
  EXPECT_GT(all[8], floor_score + 1.0);
}

void expectRejected(const LikelihoodFieldModelParams& p, const std::string& name) {
  try {
    LikelihoodFieldModel model(wallGrid(8), p);
    ADD_FAILURE() << name << " accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string::npos, std::string(e.what()).find(name)) << e.what();
  }
}

TEST(LikelihoodFieldModel, ExponentScalesTheScanLogLikelihood) {
  // One beam ending 0.15 m short of the wall (x = 0.7 m vs the wall's centre at
  // 0.85 m): the tempered model scores a quarter of the plain one.
  LikelihoodFieldModelParams p = params();
  const LikelihoodFieldModel plain(wallGrid(8), p);
  p.likelihood_exponent = 0.25;
  const LikelihoodFieldModel tempered(wallGrid(8), p);
  const LaserScan scan = quarterScan({0.65f, 0.0f, 0.0f, 0.0f});
  const Pose2 pose{0.05, 0.25, 0.0};
  const double full = plain.logLikelihood(plain.prepare(scan), pose);
  EXPECT_LT(full, kLogP0);
  EXPECT_NEAR(0.25 * full, tempered.logLikelihood(tempered.prepare(scan), pose), 1e-6);
}

TEST(LikelihoodFieldModel, ThreadCountDoesNotChangeTheScores) {
  LikelihoodFieldModelParams p = params();
  const LikelihoodFieldModel one(wallGrid(8), p);
  p.threads = 3;
  const LikelihoodFieldModel three(wallGrid(8), p);
  ParticleSet set;
  // Enough particles for three threads (particle_blocks.h), not a multiple of three.
  set.resize(3 * kMinParticlesPerThread + 1);
  Random random(3);
  for (std::size_t i = 0; i < set.size(); ++i) {
    set.setPose(i, {random.uniform(0.0, 1.0), random.uniform(0.0, 0.5), random.uniform(-3, 3)});
  }
  const LaserScan scan = quarterScan({0.3f, 0.2f, 0.4f, 0.25f});
  std::vector<double> a, b;
  one.logLikelihoods(one.prepare(scan), set, &a);
  three.logLikelihoods(three.prepare(scan), set, &b);
  EXPECT_EQ(a, b);
}

TEST(LikelihoodFieldModel, InvalidParametersThrowNamingThem) {
  using P = LikelihoodFieldModelParams;
  auto with = [](auto change) {
    P p = params();
    change(p);
    return p;
  };
  expectRejected(with([](P& p) { p.z_hit = -0.1; }), "laser_z_hit");
  expectRejected(with([](P& p) { p.z_hit = NAN; }), "laser_z_hit");
  expectRejected(with([](P& p) { p.z_rand = -0.1; }), "laser_z_rand");
  expectRejected(with([](P& p) { p.z_hit = p.z_rand = 0.0; }), "laser_z_hit + laser_z_rand");
  expectRejected(with([](P& p) { p.sigma_hit = 0.0; }), "laser_sigma_hit");
  expectRejected(with([](P& p) { p.sigma_hit = -1.0; }), "laser_sigma_hit");
  expectRejected(with([](P& p) { p.sigma_hit = INFINITY; }), "laser_sigma_hit");
  expectRejected(with([](P& p) { p.max_beams = 0; }), "laser_max_beams");
  expectRejected(with([](P& p) { p.range_min = -1.0; }), "laser_min_range");
  expectRejected(with([](P& p) { p.range_max = -1.0; }), "laser_max_range");
  expectRejected(with([](P& p) { p.max_distance = 0.0; }), "max_dist");
  expectRejected(with([](P& p) { p.max_distance = NAN; }), "max_dist");
  expectRejected(with([](P& p) { p.likelihood_exponent = 0.0; }), "laser_likelihood_exponent");
  expectRejected(with([](P& p) { p.likelihood_exponent = 1.5; }), "laser_likelihood_exponent");
  // Only z_hit or only z_rand is fine.
  EXPECT_NO_THROW(LikelihoodFieldModel(wallGrid(8), with([](P& p) { p.z_rand = 0.0; })));
  EXPECT_NO_THROW(LikelihoodFieldModel(wallGrid(8), with([](P& p) { p.z_hit = 0.0; })));
}

}  // namespace
}  // namespace pf

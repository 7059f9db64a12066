#include "pf_localization/core/sensor/laser_scan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace pf {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

LaserScan validScan() {
  LaserScan scan;
  scan.ranges = {1.0f, 2.0f, 3.0f};
  scan.angle_min = -0.5;
  scan.angle_increment = 0.5;
  scan.range_min = 0.1;
  scan.range_max = 10.0;
  return scan;
}

// The error message, or "" when the scan is valid.
std::string error(const LaserScan& scan) {
  const auto e = validateScan(scan);
  return e ? *e : std::string();
}

void expectErrorMentions(const LaserScan& scan, const std::string& word) {
  const std::string e = error(scan);
  EXPECT_FALSE(e.empty()) << "expected an error mentioning " << word;
  EXPECT_NE(std::string::npos, e.find(word)) << "error \"" << e << "\" lacks " << word;
}

TEST(ValidateScan, AcceptsAUsableScan) {
  EXPECT_FALSE(validateScan(validScan()).has_value());
  LaserScan scan = validScan();
  scan.angle_increment = -0.5;  // counter-clockwise scanners exist
  EXPECT_FALSE(validateScan(scan).has_value());
  scan.ranges = {kNaN, kNaN};  // bad beams are not a bad scan
  EXPECT_FALSE(validateScan(scan).has_value());
}

TEST(ValidateScan, RejectsEmptyRanges) {
  LaserScan scan = validScan();
  scan.ranges.clear();
  expectErrorMentions(scan, "no ranges");
}

TEST(ValidateScan, RejectsZeroOrNonFiniteIncrement) {
  LaserScan scan = validScan();
  scan.angle_increment = 0.0;
  expectErrorMentions(scan, "angle_increment");
  scan.angle_increment = std::nan("");
  expectErrorMentions(scan, "angle_increment");
  scan.angle_increment = std::numeric_limits<double>::infinity();
  expectErrorMentions(scan, "angle_increment");
}

TEST(ValidateScan, RejectsNonFiniteAngleMin) {
  LaserScan scan = validScan();
  scan.angle_min = std::nan("");
  expectErrorMentions(scan, "angle_min");
}

TEST(ValidateScan, RejectsRangeMaxNotAboveRangeMin) {
  LaserScan scan = validScan();
  scan.range_max = scan.range_min;
  expectErrorMentions(scan, "range_max");
  scan.range_max = 0.05;  // below range_min = 0.1
  expectErrorMentions(scan, "range_max");
  scan.range_max = std::numeric_limits<double>::infinity();
  expectErrorMentions(scan, "range_max");
  scan.range_max = std::nan("");
  expectErrorMentions(scan, "range_max");
  scan.range_max = 10.0;
  scan.range_min = std::nan("");
  expectErrorMentions(scan, "range_min");
}

TEST(ValidateScan, RejectsNonFiniteSensorPose) {
  for (int i = 0; i < 3; ++i) {
    LaserScan scan = validScan();
    double* field[] = {&scan.sensor_pose.x, &scan.sensor_pose.y, &scan.sensor_pose.yaw};
    *field[i] = std::nan("");
    expectErrorMentions(scan, "pose");
  }
}

// 10 beams from -0.9 rad, 0.2 rad apart, 4 of them invalid:
//   index  0    1    2    3    4    5    6    7    8    9
//   range  1    NaN  2    3    inf  4    0    5    -1   6
// The valid ones are 0, 2, 3, 5, 7, 9.
LaserScan tenBeams() {
  LaserScan scan;
  scan.ranges = {1.0f, kNaN, 2.0f, 3.0f, kInf, 4.0f, 0.0f, 5.0f, -1.0f, 6.0f};
  scan.angle_min = -0.9;
  scan.angle_increment = 0.2;
  scan.range_min = 0.1;
  scan.range_max = 10.0;
  return scan;
}

float bearingOf(const LaserScan& scan, int i) {
  return static_cast<float>(scan.angle_min + i * scan.angle_increment);
}

TEST(SelectBeams, KeepsAllValidBeamsWithTheirBearings) {
  const LaserScan scan = tenBeams();
  std::size_t valid = 0;
  const std::vector<Beam> beams = selectBeams(scan, 0, 0.0, 0.0, &valid);
  EXPECT_EQ(6u, valid);
  const int kept[] = {0, 2, 3, 5, 7, 9};
  ASSERT_EQ(6u, beams.size());
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(scan.ranges[kept[k]], beams[k].range);
    EXPECT_FLOAT_EQ(bearingOf(scan, kept[k]), beams[k].bearing);
  }
  EXPECT_FLOAT_EQ(-0.9f, beams[0].bearing);
  EXPECT_FLOAT_EQ(0.9f, beams[5].bearing);
}

TEST(SelectBeams, DropsInvalidBeamsBeforeSubsampling) {
  const LaserScan scan = tenBeams();
  std::size_t valid = 0;
  // valid[k * 6 / 3] for k = 0, 1, 2: valid[0], valid[2], valid[4], that is
  // beams 0, 3 and 7. Subsampling the raw array first would have picked
  // beams 0, 3 and 6, and beam 6 is a dropout.
  const std::vector<Beam> beams = selectBeams(scan, 3, 0.0, 0.0, &valid);
  EXPECT_EQ(6u, valid);
  ASSERT_EQ(3u, beams.size());
  EXPECT_EQ(1.0f, beams[0].range);
  EXPECT_EQ(3.0f, beams[1].range);
  EXPECT_EQ(5.0f, beams[2].range);
  EXPECT_FLOAT_EQ(-0.9f, beams[0].bearing);  // -0.9 + 0 * 0.2
  EXPECT_FLOAT_EQ(-0.3f, beams[1].bearing);  // -0.9 + 3 * 0.2
  EXPECT_FLOAT_EQ(0.5f, beams[2].bearing);   // -0.9 + 7 * 0.2
}

TEST(SelectBeams, SubsamplesEvenlyOverTheValidBeams) {
  const LaserScan scan = tenBeams();
  // max 4: valid[0], valid[6/4 = 1], valid[12/4 = 3], valid[18/4 = 4] = beams 0, 2, 5, 7.
  const std::vector<Beam> four = selectBeams(scan, 4);
  ASSERT_EQ(4u, four.size());
  EXPECT_EQ(1.0f, four[0].range);
  EXPECT_EQ(2.0f, four[1].range);
  EXPECT_EQ(4.0f, four[2].range);
  EXPECT_EQ(5.0f, four[3].range);
  // max 1: only valid[0].
  const std::vector<Beam> one = selectBeams(scan, 1);
  ASSERT_EQ(1u, one.size());
  EXPECT_EQ(1.0f, one[0].range);
  // As many as or more than the valid beams, or a non-positive max: all of them.
  EXPECT_EQ(6u, selectBeams(scan, 6).size());
  EXPECT_EQ(6u, selectBeams(scan, 100).size());
  EXPECT_EQ(6u, selectBeams(scan, -1).size());
}

TEST(SelectBeams, DropsEveryKindOfInvalidRange) {
  LaserScan scan;
  scan.angle_min = 0.0;
  scan.angle_increment = 0.1;
  scan.range_min = 0.5;
  scan.range_max = 8.0;
  //              NaN   inf   -inf   0     -2     0.25 (<min)  0.5 (=min)  8 (=max)  9 (>max)  7.5
  scan.ranges = {kNaN, kInf, -kInf, 0.0f, -2.0f, 0.25f, 0.5f, 8.0f, 9.0f, 7.5f};
  std::size_t valid = 0;
  const std::vector<Beam> beams = selectBeams(scan, 0, 0.0, 0.0, &valid);
  // range_min itself is a driver's "too close", as amcl takes it.
  EXPECT_EQ(1u, valid);
  ASSERT_EQ(1u, beams.size());
  EXPECT_EQ(7.5f, beams[0].range);
  EXPECT_FLOAT_EQ(0.9f, beams[0].bearing);
}

TEST(SelectBeams, AllInvalidGivesNothing) {
  LaserScan scan = tenBeams();
  scan.ranges.assign(10, kNaN);
  std::size_t valid = 99;
  EXPECT_TRUE(selectBeams(scan, 3, 0.0, 0.0, &valid).empty());
  EXPECT_EQ(0u, valid);
}

TEST(SelectBeams, NegativeIncrementGivesDecreasingBearings) {
  LaserScan scan = validScan();
  scan.angle_min = 1.0;
  scan.angle_increment = -0.25;
  const std::vector<Beam> beams = selectBeams(scan, 0);
  ASSERT_EQ(3u, beams.size());
  EXPECT_FLOAT_EQ(1.0f, beams[0].bearing);
  EXPECT_FLOAT_EQ(0.75f, beams[1].bearing);
  EXPECT_FLOAT_EQ(0.5f, beams[2].bearing);
}

TEST(SelectBeams, RangeOverridesOnlyNarrowTheScanLimits) {
  const LaserScan scan = tenBeams();  // valid ranges 1..6, limits [0.1, 10)
  auto ranges = [&](double lo, double hi) {
    std::vector<float> out;
    for (const Beam& b : selectBeams(scan, 0, lo, hi)) out.push_back(b.range);
    return out;
  };
  EXPECT_EQ((std::vector<float>{3, 4, 5, 6}), ranges(2.5, 0.0));  // tighter minimum
  EXPECT_EQ((std::vector<float>{3, 4, 5, 6}), ranges(2.0, 0.0));  // 2.0 itself is "too close"
  EXPECT_EQ((std::vector<float>{1, 2, 3, 4}), ranges(0.0, 5.0));  // 5.0 is at the max
  EXPECT_EQ((std::vector<float>{3, 4}), ranges(2.5, 4.5));
  // Looser than the scan's: the scan's own limits stay.
  LaserScan narrow = scan;
  narrow.range_min = 1.5;
  narrow.range_max = 5.5;
  std::vector<float> kept;
  for (const Beam& b : selectBeams(narrow, 0, 0.5, 20.0)) kept.push_back(b.range);
  EXPECT_EQ((std::vector<float>{2, 3, 4, 5}), kept);
  kept.clear();
  for (const Beam& b : selectBeams(narrow, 0, -1.0, -1.0)) kept.push_back(b.range);
  EXPECT_EQ((std::vector<float>{2, 3, 4, 5}), kept);
}

}  // namespace
}  // namespace pf

#include "pf_localization/core/sensor/cloud_scan_reducer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace pf {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kDeg = M_PI / 180.0;

// The bearing of bin k's centre (cloud_scan_reducer.h: -pi + k * width).
double binBearing(const LaserScan& scan, int k) {
  return scan.angle_min + k * scan.angle_increment;
}

// Builds clouds from points given in the base frame, converted to the
// sensor frame of `mount`: p = R^T (q - t).
class CloudBuilder {
 public:
  explicit CloudBuilder(const SensorMount& mount) : mount_(mount) {}

  void addBase(const Eigen::Vector3d& q) {
    const Eigen::Vector3d p = mount_.rotation.transpose() * (q - mount_.translation);
    points_.push_back(
        {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  }
  // A point at base-frame height `z`, horizontal distance `d` from the
  // sensor's vertical axis, at `bearing` (base frame, about that axis).
  void addPolar(double bearing, double d, double z) {
    const Eigen::Vector3d& t = mount_.translation;
    addBase({t.x() + d * std::cos(bearing), t.y() + d * std::sin(bearing), z});
  }
  void addRaw(CloudPoint p) { points_.push_back(p); }
  const std::vector<CloudPoint>& points() const { return points_; }

 private:
  SensorMount mount_;
  std::vector<CloudPoint> points_;
};

std::size_t countedTotal(const CloudScanCounts& n) {
  return n.not_finite + n.below_band + n.above_band + n.too_near + n.too_far + n.kept;
}

std::size_t filledBins(const LaserScan& scan) {
  std::size_t filled = 0;
  for (float r : scan.ranges) filled += std::isfinite(r) ? 1 : 0;
  return filled;
}

// A level lidar 0.6 m up in a room whose wall x = 3 m (base frame) faces it
// over +-45 degrees; the floor (z 0) and a 2.5 m ceiling are seen in every
// direction, and nearer than the wall in front of it.
TEST(CloudScan, WallGivesItsRangeAndFloorAndCeilingNothing) {
  const SensorMount mount = SensorMount::fromRpy(0.0, 0.0, 0.6, 0.0, 0.0, 0.0);
  CloudScanParams params;  // the default band, 0.3-0.9 m
  const CloudScanReducer reducer(params);
  ASSERT_EQ(reducer.bins(), 720);
  CloudBuilder cloud(mount);
  std::size_t floor = 0, ceiling = 0, wall = 0;
  // Points exactly on the bins' centres, so that each bin's range is exact.
  for (int k = 0; k < 720; ++k) {
    const double bearing = -M_PI + k * 0.5 * kDeg;
    for (double d : {1.0, 2.0, 4.0}) {
      cloud.addPolar(bearing, d, 0.0);
      cloud.addPolar(bearing, d, 2.5);
      floor++, ceiling++;
    }
    if (std::fabs(bearing) <= 45.0 * kDeg + 1e-9) {
      for (double z : {0.35, 0.6, 0.85})
        cloud.addPolar(bearing, 3.0 / std::cos(bearing), z), wall++;
    }
  }
  const CloudScan out = reducer.reduce(cloud.points(), mount);
  const LaserScan& scan = out.scan;
  ASSERT_FALSE(validateScan(scan).has_value()) << *validateScan(scan);
  EXPECT_EQ(scan.ranges.size(), 720u);
  EXPECT_NEAR(scan.angle_increment, 0.5 * kDeg, 1e-15);
  EXPECT_EQ(scan.angle_min, -M_PI);
  int wall_bins = 0;
  for (int k = 0; k < 720; ++k) {
    const double bearing = binBearing(scan, k);
    if (std::fabs(bearing) <= 45.0 * kDeg + 1e-9) {
      ++wall_bins;
      EXPECT_NEAR(scan.ranges[k], 3.0 / std::cos(bearing), 1e-5) << "bin " << k;
    } else {
      EXPECT_TRUE(std::isnan(scan.ranges[k])) << "bin " << k << " reads " << scan.ranges[k];
    }
  }
  EXPECT_EQ(wall_bins, 181);
  EXPECT_EQ(out.counts.points, cloud.points().size());
  EXPECT_EQ(out.counts.below_band, floor);
  EXPECT_EQ(out.counts.above_band, ceiling);
  EXPECT_EQ(out.counts.kept, wall);
  EXPECT_EQ(out.counts.bins_filled, 181u);
  EXPECT_EQ(countedTotal(out.counts), out.counts.points);
}

TEST(CloudScan, ClutterBelowAndAboveTheBandIsDroppedAndInsideItKept) {
  const SensorMount mount = SensorMount::fromRpy(0.0, 0.0, 0.6, 0.0, 0.0, 0.0);
  CloudScanParams params;
  params.min_height = 0.3;
  params.max_height = 0.9;
  const CloudScanReducer reducer(params);
  CloudBuilder cloud(mount);
  // Behind everything, a wall 4 m away in every direction.
  for (int k = 0; k < 720; ++k) cloud.addPolar(-M_PI + k * 0.5 * kDeg, 4.0, 0.6);
  // Bearings 10-20 deg: a parcel 0.2 m high, 1.5 m away (its top and face).
  // 40-50 deg: a shelf hanging at 1.2-1.8 m, 1 m away.
  // 70-80 deg: a table top at 1.0 m, 2 m away, on a leg (inside the band) at 75.
  // 100-110 deg: a box 0.8 m high, 2.5 m away: inside the band, an obstacle.
  for (double deg = 10.0; deg <= 20.0; deg += 0.5) {
    for (double z : {0.0, 0.1, 0.2}) cloud.addPolar(deg * kDeg, 1.5, z);
  }
  for (double deg = 40.0; deg <= 50.0; deg += 0.5) {
    for (double z : {1.2, 1.5, 1.8}) cloud.addPolar(deg * kDeg, 1.0, z);
  }
  for (double deg = 70.0; deg <= 80.0; deg += 0.5) cloud.addPolar(deg * kDeg, 2.0, 1.0);
  for (double z : {0.1, 0.5, 0.8}) cloud.addPolar(75.0 * kDeg, 2.0, z);
  for (double deg = 100.0; deg <= 110.0; deg += 0.5) {
    for (double z : {0.35, 0.6}) cloud.addPolar(deg * kDeg, 2.5, z);
  }
  const CloudScan out = reducer.reduce(cloud.points(), mount);
  const auto rangeAt = [&](double deg) {
    return out.scan.ranges[static_cast<int>(std::lround((deg + 180.0) / 0.5)) % 720];
  };
  for (double deg : {10.0, 15.0, 20.0, 40.0, 45.0, 50.0, 70.0, 74.5, 75.5, 80.0, -90.0}) {
    EXPECT_NEAR(rangeAt(deg), 4.0, 1e-5) << deg << " deg";
  }
  EXPECT_NEAR(rangeAt(75.0), 2.0, 1e-5) << "the table's leg is in the band";
  for (double deg : {100.0, 105.0, 110.0}) EXPECT_NEAR(rangeAt(deg), 2.5, 1e-5) << deg << " deg";
  EXPECT_EQ(out.counts.below_band, 21u * 3 + 1);   // the parcel, the leg's foot
  EXPECT_EQ(out.counts.above_band, 21u * 3 + 21);  // the shelf, the table top
  EXPECT_EQ(out.counts.bins_filled, 720u);
}

// The beam end of bin k, in the base frame: where the filter will put it.
Eigen::Vector2d beamEnd(const LaserScan& scan, int k) {
  const double a = scan.sensor_pose.yaw + binBearing(scan, k);
  return {scan.sensor_pose.x + scan.ranges[k] * std::cos(a),
          scan.sensor_pose.y + scan.ranges[k] * std::sin(a)};
}

// A lidar tipped 10 deg nose down and 5 deg sideways, off the robot's centre
// and turned: the height test must use the base frame's z (the floor ahead
// is far above the sensor's own z = -0.6 plane in the tilted frame), and the
// beams must start at the sensor and end on the wall.
TEST(CloudScan, TiltedOffsetMountingProjectsIntoTheBaseFrame) {
  const double heading = 30.0 * kDeg;
  const SensorMount mount = SensorMount::fromRpy(0.3, -0.1, 0.6, 5.0 * kDeg, 10.0 * kDeg, heading);
  const CloudScanReducer reducer(CloudScanParams{});
  CloudBuilder cloud(mount);
  std::size_t floor = 0;
  for (int k = 0; k < 720; ++k) {
    // Bin k's bearing is about the vertical through the sensor, from its heading.
    const double bearing = heading + (-M_PI + k * 0.5 * kDeg);
    for (double d : {0.5, 1.0, 2.0, 3.0, 6.0}) cloud.addPolar(bearing, d, 0.0), floor++;
    const double c = std::cos(bearing);
    if (c > 0.3) {  // the wall x = 3 in the base frame
      for (double z : {0.4, 0.8}) cloud.addPolar(bearing, (3.0 - 0.3) / c, z);
    }
  }
  const CloudScan out = reducer.reduce(cloud.points(), mount);
  const LaserScan& scan = out.scan;
  EXPECT_NEAR(scan.sensor_pose.x, 0.3, 1e-12);
  EXPECT_NEAR(scan.sensor_pose.y, -0.1, 1e-12);
  EXPECT_NEAR(scan.sensor_pose.yaw, heading, 1e-12);
  EXPECT_EQ(out.counts.below_band, floor);
  ASSERT_GT(out.counts.bins_filled, 200u);
  EXPECT_EQ(out.counts.bins_filled, filledBins(scan));
  for (int k = 0; k < 720; ++k) {
    if (!std::isfinite(scan.ranges[k])) continue;
    const Eigen::Vector2d end = beamEnd(scan, k);
    EXPECT_NEAR(end.x(), 3.0, 1e-5) << "bin " << k;
  }
  // The same cloud read as if the sensor were level would see the floor.
  const SensorMount level = SensorMount::fromRpy(0.3, -0.1, 0.6, 0.0, 0.0, heading);
  EXPECT_LT(reducer.reduce(cloud.points(), level).counts.below_band, floor);
}

// A depth camera's optical frame: z forward, x right, y down (roll -90,
// yaw -90). Its heading is that of its x axis, the robot's right; a point
// straight ahead of the camera must still end up straight ahead of the robot.
TEST(CloudScan, OpticalFrameCamera) {
  const SensorMount mount = SensorMount::fromRpy(0.2, 0.0, 0.5, -M_PI / 2, 0.0, -M_PI / 2);
  const CloudScanReducer reducer(CloudScanParams{});
  const std::vector<CloudPoint> points = {{0.0f, 0.0f, 2.0f}, {1.0f, 0.0f, 1.0f}};
  const CloudScan out = reducer.reduce(points, mount);
  EXPECT_NEAR(out.scan.sensor_pose.yaw, -M_PI / 2, 1e-12);
  ASSERT_EQ(out.counts.bins_filled, 2u);
  std::vector<Eigen::Vector2d> ends;
  for (int k = 0; k < reducer.bins(); ++k) {
    if (std::isfinite(out.scan.ranges[k])) ends.push_back(beamEnd(out.scan, k));
  }
  ASSERT_EQ(ends.size(), 2u);
  // In bearing order: the point to the right (camera x = 1, z = 1) first.
  EXPECT_NEAR(ends[0].x(), 1.2, 1e-6);
  EXPECT_NEAR(ends[0].y(), -1.0, 1e-6);
  EXPECT_NEAR(ends[1].x(), 2.2, 1e-6);
  EXPECT_NEAR(ends[1].y(), 0.0, 1e-6);
}

TEST(CloudScan, NonFinitePointsAreCountedAndEmptyBinsReadNoReading) {
  const SensorMount mount = SensorMount::fromRpy(0.0, 0.0, 0.6, 0.0, 0.0, 0.0);
  const CloudScanReducer reducer(CloudScanParams{});
  std::vector<CloudPoint> points = {
      {kNaN, kNaN, kNaN},  {1.0f, kNaN, 0.0f}, {kInf, 0.0f, 0.0f},
      {0.0f, 0.0f, -kInf}, {2.0f, 0.0f, 0.0f},  // one real point, straight ahead at 2 m
  };
  const CloudScan out = reducer.reduce(points, mount);
  EXPECT_EQ(out.counts.points, 5u);
  EXPECT_EQ(out.counts.not_finite, 4u);
  EXPECT_EQ(out.counts.kept, 1u);
  EXPECT_EQ(out.counts.bins_filled, 1u);
  EXPECT_EQ(out.scan.ranges[360], 2.0f);  // bin 360 is centred on bearing 0
  std::size_t nan_bins = 0;
  for (float r : out.scan.ranges) nan_bins += std::isnan(r) ? 1 : 0;
  EXPECT_EQ(nan_bins, 719u);
  // selectBeams (laser_scan.h) sees one beam: the empty bins are no readings.
  const std::vector<Beam> beams = selectBeams(out.scan, 0);
  ASSERT_EQ(beams.size(), 1u);
  EXPECT_EQ(beams[0].index, 360u);
  EXPECT_NEAR(beams[0].bearing, 0.0, 1e-6);

  const CloudScan empty = reducer.reduce({}, mount);
  EXPECT_EQ(empty.counts.points, 0u);
  EXPECT_EQ(empty.counts.bins_filled, 0u);
  EXPECT_EQ(empty.scan.ranges.size(), 720u);
  EXPECT_TRUE(selectBeams(empty.scan, 0).empty());
}

TEST(CloudScan, RangeLimitsAreHorizontalDistancesFromTheSensorsAxis) {
  const SensorMount mount = SensorMount::fromRpy(0.0, 0.0, 0.6, 0.0, 0.0, 0.0);
  CloudScanParams params;
  params.min_range = 0.25;
  params.max_range = 10.0;
  const CloudScanReducer reducer(params);
  // The mast 0.1 m from the axis, in the band; a point 0.2 m out but 0.25 m
  // up (0.32 m in 3D: its horizontal distance decides); 10 m exactly (out)
  // and 9.9 m (in).
  const std::vector<CloudPoint> points = {
      {0.1f, 0.0f, 0.0f}, {0.0f, 0.2f, 0.25f}, {-10.0f, 0.0f, 0.0f}, {0.0f, -9.9f, 0.0f}};
  const CloudScan out = reducer.reduce(points, mount);
  EXPECT_EQ(out.counts.too_near, 2u);
  EXPECT_EQ(out.counts.too_far, 1u);
  EXPECT_EQ(out.counts.kept, 1u);
  EXPECT_EQ(out.scan.range_min, 0.25);
  EXPECT_EQ(out.scan.range_max, 10.0);
  EXPECT_NEAR(out.scan.ranges[180], 9.9f, 1e-6);  // bearing -90 deg
  EXPECT_EQ(countedTotal(out.counts), 4u);
}

TEST(CloudScan, BinsCloseTheCircleAndWrapAtPi) {
  CloudScanParams params;
  params.bin_width = 0.7 * kDeg;  // 514.3 bins: rounded up, narrowed to fit
  const CloudScanReducer reducer(params);
  EXPECT_EQ(reducer.bins(), 515);
  const SensorMount mount = SensorMount::fromRpy(0.0, 0.0, 0.6, 0.0, 0.0, 0.0);
  const double w = 2.0 * M_PI / 515;
  const auto pointAt = [](double bearing, double d) {
    return CloudPoint{static_cast<float>(d * std::cos(bearing)),
                      static_cast<float>(d * std::sin(bearing)), 0.0f};
  };
  // Bin 0 is centred on -pi and reaches half a bin either side: a point just
  // below +pi is in it, as is one just above -pi; a point past half a bin is in bin 1.
  const std::vector<CloudPoint> points = {
      pointAt(M_PI - 0.2 * w, 1.0), pointAt(-M_PI + 0.2 * w, 2.0), pointAt(-M_PI + 0.7 * w, 3.0)};
  const CloudScan out = reducer.reduce(points, mount);
  EXPECT_NEAR(out.scan.angle_increment, w, 1e-15);
  ASSERT_EQ(out.scan.ranges.size(), 515u);
  EXPECT_NEAR(out.scan.ranges[0], 1.0f, 1e-6);  // the nearer of the two
  EXPECT_NEAR(out.scan.ranges[1], 3.0f, 1e-6);
  EXPECT_EQ(out.counts.bins_filled, 2u);

  params.bin_width = 1.0 * kDeg;
  EXPECT_EQ(CloudScanReducer(params).bins(), 360);
}

// The message of a refused value: std::invalid_argument's text.
std::string refusal(const CloudScanParams& params) {
  try {
    validate(params);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

void expectRefused(const CloudScanParams& params, const std::vector<std::string>& words) {
  const std::string message = refusal(params);
  ASSERT_FALSE(message.empty()) << "accepted, expected a refusal naming " << words[0];
  for (const std::string& w : words) {
    EXPECT_NE(message.find(w), std::string::npos) << "\"" << message << "\" lacks \"" << w << "\"";
  }
  EXPECT_THROW(CloudScanReducer{params}, std::invalid_argument);
}

TEST(CloudScanParams, DefaultsAreValidAndBadValuesAreNamed) {
  EXPECT_EQ(refusal(CloudScanParams{}), "");
  CloudScanParams p;
  p.bin_width = 0.0;
  expectRefused(p, {"cloud_bin_width", "= 0", "[0.001, 0.785398", "rad"});
  p = {};
  p.bin_width = 1.0;
  expectRefused(p, {"cloud_bin_width", "= 1", "0.785398"});
  p = {};
  p.min_range = -0.1;
  expectRefused(p, {"cloud_min_range", "= -0.1", ">= 0", "m"});
  p = {};
  p.max_range = 0.0;
  expectRefused(p, {"cloud_max_range", "= 0", "> 0"});
  p = {};
  p.min_range = 5.0;
  p.max_range = 4.0;
  expectRefused(p, {"cloud_max_range", "= 4", "> cloud_min_range"});
  p = {};
  p.min_height = 1.0;
  p.max_height = 0.5;
  expectRefused(p, {"cloud_max_height", "= 0.5", "> cloud_min_height"});
  p = {};
  p.min_height = std::nan("");
  expectRefused(p, {"cloud_min_height", "finite"});
  p = {};
  p.max_height = std::numeric_limits<double>::infinity();
  expectRefused(p, {"cloud_max_height", "finite"});
}

TEST(CloudScanParams, TableNamesEveryParameterWithItsUnit) {
  const auto& table = cloudScanParameters();
  ASSERT_EQ(table.size(), 5u);
  const std::vector<std::pair<std::string, std::string>> expected = {{"cloud_min_height", "m"},
                                                                     {"cloud_max_height", "m"},
                                                                     {"cloud_bin_width", "rad"},
                                                                     {"cloud_min_range", "m"},
                                                                     {"cloud_max_range", "m"}};
  for (const auto& [name, unit] : expected) {
    const Parameter<CloudScanParams>* row = findParameter(table, name);
    ASSERT_NE(row, nullptr) << name;
    EXPECT_EQ(row->info.unit, unit) << name;
    EXPECT_EQ(row->info.amcl_kind, Amcl::kOursOnly) << name;
  }
  // The table reaches the struct's members.
  CloudScanParams p;
  std::get<Field<CloudScanParams, double>>(findParameter(table, "cloud_bin_width")->field)
      .set(p, 0.01);
  EXPECT_EQ(p.bin_width, 0.01);
}

TEST(SensorMount, FromRpyIsZyxAsTfAndUrdf) {
  const SensorMount m = SensorMount::fromRpy(1.0, 2.0, 3.0, 0.1, -0.4, 2.5);
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_LT((m.rotation - expected).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_EQ(m.translation, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_FALSE(validateMount(m).has_value());
}

TEST(SensorMount, BadMountingsAreRefused) {
  const CloudScanReducer reducer(CloudScanParams{});
  const std::vector<CloudPoint> points = {{1.0f, 0.0f, 0.0f}};
  SensorMount m;
  m.translation.z() = std::nan("");
  ASSERT_TRUE(validateMount(m).has_value());
  EXPECT_NE(validateMount(m)->find("not finite"), std::string::npos);
  EXPECT_THROW(reducer.reduce(points, m), std::invalid_argument);
  m = SensorMount{};
  m.rotation *= 1.01;  // a scaled rotation
  ASSERT_TRUE(validateMount(m).has_value());
  EXPECT_NE(validateMount(m)->find("not a rotation"), std::string::npos);
  m = SensorMount{};
  m.rotation(2, 2) = -1.0;  // a reflection
  EXPECT_TRUE(validateMount(m).has_value());
  EXPECT_THROW(reducer.reduce(points, m), std::invalid_argument);
}

// A sensor whose x axis points straight down has no heading of its own: the
// scan takes the base frame's, and the beams still end where the points are.
TEST(SensorMount, VerticalXAxisFallsBackToTheBaseHeading) {
  const SensorMount mount = SensorMount::fromRpy(0.0, 0.0, 0.6, 0.0, M_PI / 2, 0.0);
  const CloudScanReducer reducer(CloudScanParams{});
  CloudBuilder cloud(mount);
  cloud.addBase({-2.0, 1.0, 0.6});
  const CloudScan out = reducer.reduce(cloud.points(), mount);
  EXPECT_EQ(out.scan.sensor_pose.yaw, 0.0);
  ASSERT_EQ(out.counts.bins_filled, 1u);
  for (int k = 0; k < reducer.bins(); ++k) {
    if (!std::isfinite(out.scan.ranges[k])) continue;
    // Within half a bin (0.25 deg at 2.2 m: 0.01 m) of the point.
    const Eigen::Vector2d end = beamEnd(out.scan, k);
    EXPECT_NEAR(end.x(), -2.0, 0.02);
    EXPECT_NEAR(end.y(), 1.0, 0.02);
  }
}

}  // namespace
}  // namespace pf

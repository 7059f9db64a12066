#include "pf_localization/ros/input/point_cloud.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/ros/input/conversions.h"

namespace pf_ros {
namespace {

using sensor_msgs::PointField;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A width x height cloud with float32 x y z and a float32 intensity, point
// (r, c) at (r, c, r + c) unless set otherwise.
sensor_msgs::PointCloud2 xyziCloud(uint32_t width, uint32_t height) {
  sensor_msgs::PointCloud2 msg;
  msg.width = width;
  msg.height = height;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2Fields(4, "x", 1, PointField::FLOAT32, "y", 1, PointField::FLOAT32, "z", 1,
                                PointField::FLOAT32, "intensity", 1, PointField::FLOAT32);
  if (width * height == 0) return msg;  // no data for an iterator to point into
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z"),
      i(msg, "intensity");
  for (uint32_t r = 0; r < height; ++r) {
    for (uint32_t c = 0; c < width; ++c, ++x, ++y, ++z, ++i) {
      *x = static_cast<float>(r);
      *y = static_cast<float>(c);
      *z = static_cast<float>(r + c);
      *i = 7.0f;
    }
  }
  return msg;
}

std::optional<CloudReadError::Kind> errorKind(const sensor_msgs::PointCloud2& msg,
                                              std::string* detail = nullptr) {
  std::vector<pf::CloudPoint> points = {{1.0f, 2.0f, 3.0f}};
  const std::optional<CloudReadError> e = readCloud(msg, &points);
  if (!e) return std::nullopt;
  EXPECT_TRUE(points.empty()) << "a refused cloud leaves no points";
  if (detail) *detail = e->detail;
  return e->kind;
}

TEST(ReadCloud, OrganizedCloudInRowOrder) {
  const sensor_msgs::PointCloud2 msg = xyziCloud(5, 3);
  std::vector<pf::CloudPoint> points;
  ASSERT_FALSE(readCloud(msg, &points).has_value());
  ASSERT_EQ(points.size(), 15u);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 5; ++c) {
      const pf::CloudPoint& p = points[r * 5 + c];
      EXPECT_EQ(p.x, r);
      EXPECT_EQ(p.y, c);
      EXPECT_EQ(p.z, r + c);
    }
  }
}

TEST(ReadCloud, UnorganizedCloudAndFieldsInAnyOrder) {
  // z first, then a double, then y and x: offsets are what count, not order.
  sensor_msgs::PointCloud2 msg;
  msg.width = 4;
  msg.height = 1;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2Fields(4, "z", 1, PointField::FLOAT32, "t", 1, PointField::FLOAT64, "y", 1,
                                PointField::FLOAT32, "x", 1, PointField::FLOAT32);
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z");
  for (int k = 0; k < 4; ++k, ++x, ++y, ++z) {
    *x = 0.5f * k;
    *y = -1.0f * k;
    *z = 10.0f + k;
  }
  std::vector<pf::CloudPoint> points;
  ASSERT_FALSE(readCloud(msg, &points).has_value());
  ASSERT_EQ(points.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(points[k].x, 0.5f * k);
    EXPECT_EQ(points[k].y, -1.0f * k);
    EXPECT_EQ(points[k].z, 10.0f + k);
  }
}

// Rows padded by whole points: the padding is not read as points.
TEST(ReadCloud, PaddedRowsAreSkipped) {
  const sensor_msgs::PointCloud2 packed = xyziCloud(3, 2);
  sensor_msgs::PointCloud2 msg = packed;
  msg.row_step = 5 * msg.point_step;  // two points of padding per row
  msg.data.assign(2 * msg.row_step, 0xFF);
  for (int r = 0; r < 2; ++r) {
    std::copy(packed.data.begin() + r * packed.row_step,
              packed.data.begin() + (r + 1) * packed.row_step, msg.data.begin() + r * msg.row_step);
  }
  std::vector<pf::CloudPoint> points;
  ASSERT_FALSE(readCloud(msg, &points).has_value());
  ASSERT_EQ(points.size(), 6u);
  EXPECT_EQ(points[3].x, 1.0f);  // row 1, column 0
  EXPECT_EQ(points[3].y, 0.0f);
  EXPECT_EQ(points[5].z, 3.0f);
  // The last row needs no padding after it.
  msg.data.resize(msg.row_step + packed.row_step);
  EXPECT_FALSE(readCloud(msg, &points).has_value());
}

TEST(ReadCloud, MissingFieldIsNamed) {
  sensor_msgs::PointCloud2 msg;
  msg.width = 2;
  msg.height = 1;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2Fields(3, "x", 1, PointField::FLOAT32, "y", 1, PointField::FLOAT32,
                                "intensity", 1, PointField::FLOAT32);
  std::string detail;
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kMissingField);
  EXPECT_NE(detail.find("no field 'z'"), std::string::npos) << detail;
  EXPECT_NE(detail.find("x, y, intensity"), std::string::npos) << detail;

  msg.fields.clear();
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kMissingField);
  EXPECT_NE(detail.find("no field 'x'"), std::string::npos) << detail;
  EXPECT_NE(detail.find("none"), std::string::npos) << detail;
}

TEST(ReadCloud, WrongDatatypeIsNamed) {
  sensor_msgs::PointCloud2 msg;
  msg.width = 2;
  msg.height = 1;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2Fields(3, "x", 1, PointField::FLOAT32, "y", 1, PointField::FLOAT64, "z", 1,
                                PointField::FLOAT32);
  std::string detail;
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kWrongDatatype);
  EXPECT_NE(detail.find("'y'"), std::string::npos) << detail;
  EXPECT_NE(detail.find("FLOAT64"), std::string::npos) << detail;

  msg = xyziCloud(2, 1);
  msg.fields[2].datatype = PointField::INT16;
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kWrongDatatype);
  EXPECT_NE(detail.find("'z' is 1 x INT16"), std::string::npos) << detail;
  msg = xyziCloud(2, 1);
  msg.fields[0].count = 3;
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kWrongDatatype);
  EXPECT_NE(detail.find("'x' is 3 x FLOAT32"), std::string::npos) << detail;
}

TEST(ReadCloud, BigEndianIsRefused) {
  sensor_msgs::PointCloud2 msg = xyziCloud(2, 2);
  msg.is_bigendian = true;
  std::string detail;
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kBigEndian);
  EXPECT_NE(detail.find("big-endian"), std::string::npos) << detail;
  EXPECT_STREQ(kindName(CloudReadError::Kind::kBigEndian), "byte order");
}

TEST(ReadCloud, InconsistentLayoutsAreRefusedBeforeReading) {
  std::string detail;
  sensor_msgs::PointCloud2 msg = xyziCloud(4, 3);
  msg.data.resize(msg.data.size() - 1);
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kBadLayout);
  EXPECT_NE(detail.find("data holds"), std::string::npos) << detail;

  msg = xyziCloud(4, 3);
  msg.fields[2].offset = msg.point_step - 2;  // z would reach into the next point
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kBadLayout);
  EXPECT_NE(detail.find("'z' at offset"), std::string::npos) << detail;

  msg = xyziCloud(4, 3);
  msg.point_step = 0;
  EXPECT_EQ(errorKind(msg), CloudReadError::Kind::kBadLayout);

  msg = xyziCloud(4, 3);
  msg.row_step = 4 * msg.point_step - 1;
  EXPECT_EQ(errorKind(msg, &detail), CloudReadError::Kind::kBadLayout);
  EXPECT_NE(detail.find("row_step"), std::string::npos) << detail;
  msg.row_step = 4 * msg.point_step + 2;  // padding of part of a point
  EXPECT_EQ(errorKind(msg), CloudReadError::Kind::kBadLayout);
}

TEST(ReadCloud, EmptyCloudReadsNoPoints) {
  sensor_msgs::PointCloud2 msg = xyziCloud(0, 1);
  std::vector<pf::CloudPoint> points = {{1.0f, 1.0f, 1.0f}};
  EXPECT_FALSE(readCloud(msg, &points).has_value());
  EXPECT_TRUE(points.empty());
}

// NaN points (no return) are read as they are and counted by the reducer.
TEST(ReadCloud, NanPointsAreReadAndCounted) {
  sensor_msgs::PointCloud2 msg = xyziCloud(4, 2);
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z");
  for (int k = 0; k < 8; ++k, ++x, ++y, ++z) {
    if (k % 2 == 0) {
      *x = *y = *z = kNaN;
    } else {
      *x = 2.0f, *y = 0.5f * k, *z = 0.0f;
    }
  }
  std::vector<pf::CloudPoint> points;
  ASSERT_FALSE(readCloud(msg, &points).has_value());
  ASSERT_EQ(points.size(), 8u);
  EXPECT_TRUE(std::isnan(points[0].x));
  EXPECT_EQ(points[1].x, 2.0f);
  const pf::CloudScanReducer reducer(pf::CloudScanParams{});
  const pf::CloudScan out = reducer.reduce(points, pf::SensorMount::fromRpy(0, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(out.counts.points, 8u);
  EXPECT_EQ(out.counts.not_finite, 4u);
  EXPECT_EQ(out.counts.kept, 4u);
}

TEST(ToSensorMount, NormalisesTheQuaternion) {
  geometry_msgs::Transform t;
  t.translation.x = 0.1;
  t.translation.y = -0.2;
  t.translation.z = 0.6;
  // Yaw 90 deg, scaled by 2.
  t.rotation.z = 2.0 * std::sqrt(0.5);
  t.rotation.w = 2.0 * std::sqrt(0.5);
  const pf::SensorMount m = toSensorMount(t);
  EXPECT_FALSE(pf::validateMount(m).has_value());
  const pf::SensorMount expected = pf::SensorMount::fromRpy(0.1, -0.2, 0.6, 0.0, 0.0, M_PI / 2);
  EXPECT_LT((m.rotation - expected.rotation).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(m.translation, expected.translation);

  t.rotation = geometry_msgs::Quaternion();
  t.rotation.w = 0.0;  // all zero
  EXPECT_TRUE(pf::validateMount(toSensorMount(t)).has_value());
}

// Where the build wrote cloud.bag: the devel space's share/, found from this
// test's place in the devel space's lib/ or from CMAKE_PREFIX_PATH.
std::optional<std::string> cloudBagPath() {
  std::vector<std::string> prefixes;
  char exe[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  if (n > 0) {
    exe[n] = '\0';
    const std::string path(exe);
    // <devel>/lib/pf_localization/pf_ros_test
    std::string dir = path.substr(0, path.rfind('/'));
    dir = dir.substr(0, dir.rfind('/'));
    prefixes.push_back(dir.substr(0, dir.rfind('/')));
  }
  if (const char* env = std::getenv("CMAKE_PREFIX_PATH")) {
    std::string list = env;
    for (std::size_t start = 0; start <= list.size();) {
      const std::size_t end = std::min(list.find(':', start), list.size());
      prefixes.push_back(list.substr(start, end - start));
      start = end + 1;
    }
  }
  for (const std::string& prefix : prefixes) {
    const std::string bag = prefix + "/share/pf_localization/bags/cloud.bag";
    if (std::ifstream(bag).good()) return bag;
  }
  return std::nullopt;
}

// The simulator's 3D lidar and its 2D lidar share a place (velodyne and
// laser, 0.6 m above base_link): the first cloud, reduced with a band
// around that height, must read what the 2D scan at the same stamp reads.
TEST(CloudBag, FirstCloudAgreesWithTheScanAtTheSamePlace) {
  const std::optional<std::string> path = cloudBagPath();
  if (!path) GTEST_SKIP() << "no cloud.bag in the devel space (built by pf_cloud_bag)";
  rosbag::Bag bag(*path, rosbag::bagmode::Read);
  std::optional<sensor_msgs::PointCloud2> cloud;
  std::optional<geometry_msgs::Transform> mount;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (!mount && m.getTopic() == "/tf") {
      // Held: a range-for over the temporary's member would outlive it.
      const auto tf = m.instantiate<tf2_msgs::TFMessage>();
      for (const auto& t : tf->transforms) {
        if (t.header.frame_id == "base_link" && t.child_frame_id == "velodyne") {
          mount = t.transform;
        }
      }
    }
    if (!cloud && m.getTopic() == "/points") cloud = *m.instantiate<sensor_msgs::PointCloud2>();
    if (cloud && mount) break;
  }
  ASSERT_TRUE(cloud && mount) << "no /points or no base_link -> velodyne in " << *path;
  std::optional<sensor_msgs::LaserScan> scan;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/scan"))) {
    const auto s = m.instantiate<sensor_msgs::LaserScan>();
    if (s->header.stamp == cloud->header.stamp) {
      scan = *s;
      break;
    }
  }
  ASSERT_TRUE(scan) << "no /scan at the first cloud's stamp";
  ASSERT_EQ(scan->ranges.size(), 720u);
  ASSERT_NEAR(scan->angle_increment, M_PI / 360.0, 1e-6);

  std::vector<pf::CloudPoint> points;
  const std::optional<CloudReadError> error = readCloud(*cloud, &points);
  ASSERT_FALSE(error) << error->detail;
  ASSERT_EQ(points.size(), 16u * 1800u);
  pf::CloudScanParams params;  // the default band, 0.3-0.9 m, 0.5 deg bins
  params.max_range = scan->range_max;
  const pf::CloudScan out = pf::CloudScanReducer(params).reduce(points, toSensorMount(*mount));
  EXPECT_GT(out.counts.not_finite, 0u);
  EXPECT_GT(out.counts.below_band, 1000u);  // the floor
  EXPECT_GT(out.counts.above_band, 1000u);  // the ceiling
  EXPECT_EQ(out.scan.sensor_pose.x, 0.0);
  EXPECT_EQ(out.scan.sensor_pose.y, 0.0);
  EXPECT_EQ(out.scan.sensor_pose.yaw, 0.0);

  // The scan's beam i looks along i * 0.5 deg; the cloud's bin k along
  // -180 + k * 0.5 deg. A bin's range is the mean of its nearest surface's
  // points: median 8 mm from the scan (the nearest point alone, with the
  // simulator's 1.5 cm noise and up to 16 rings x 2-3 columns a bin, read
  // 32 mm short); beyond that, a bin's points spread over half a degree,
  // which at grazing incidence on a far wall is decimetres.
  std::vector<double> differences;
  for (int i = 0; i < 720; ++i) {
    const float from_scan = scan->ranges[i];
    const float from_cloud = out.scan.ranges[(i + 360) % 720];
    if (std::isfinite(from_scan) && std::isfinite(from_cloud)) {
      differences.push_back(std::fabs(from_cloud - from_scan));
    }
  }
  ASSERT_GT(differences.size(), 600u) << "bins where the cloud and the scan both read";
  std::sort(differences.begin(), differences.end());
  const double median = differences[differences.size() / 2];
  const double within_8cm =
      static_cast<double>(std::lower_bound(differences.begin(), differences.end(), 0.08) -
                          differences.begin()) /
      differences.size();
  RecordProperty("bins_compared", static_cast<int>(differences.size()));
  RecordProperty("median_difference_mm", static_cast<int>(std::lround(median * 1000)));
  EXPECT_LT(median, 0.015);
  EXPECT_GT(within_8cm, 0.9);
}

}  // namespace
}  // namespace pf_ros

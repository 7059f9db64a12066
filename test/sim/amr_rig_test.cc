#include "pf_localization/sim/amr_rig.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "pf_localization/sim/planar_sensor.h"

namespace pf::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A 10 x 10 m room of 0.05 m cells, one cell of wall all around: the walls'
// inner faces are at x, y = 0.05 and 9.95.
OccupancyGrid room() {
  const int n = 200;
  std::vector<int8_t> data(n * n, 0);
  for (int i = 0; i < n; ++i) {
    data[i] = data[(n - 1) * n + i] = data[i * n] = data[i * n + n - 1] = 100;
  }
  return OccupancyGrid(n, n, 0.05, {}, data);
}

// The beam of `lidar` whose sensor-frame angle is `angle`.
int beamAt(const PlanarLidar& lidar, double angle) {
  return static_cast<int>(std::lround((angle - lidar.angle_min) / lidar.angle_increment));
}

TEST(AmrRigTest, EachLidarRangesFromItsOwnCorner) {
  const RayCaster walls(room());
  const PlanarLidar front = amrFrontLidar(), rear = amrRearLidar();
  // Facing +x from the room's centre: the front lidar is at (5.28, 5.18)
  // looking at +45 deg, the rear one at (4.72, 4.82) looking at -135 deg.
  const Pose2 base{5.0, 5.0, 0.0};
  const auto f = idealRanges(front, walls, {}, base, 0.0);
  const auto r = idealRanges(rear, walls, {}, base, 0.0);
  EXPECT_NEAR(f[beamAt(front, -45 * kDeg)], 9.95 - 5.28, 1e-9);  // world +x
  EXPECT_NEAR(f[beamAt(front, 45 * kDeg)], 9.95 - 5.18, 1e-9);   // world +y
  EXPECT_NEAR(f[beamAt(front, 135 * kDeg)], 5.28 - 0.05, 1e-9);  // world -x
  EXPECT_NEAR(r[beamAt(rear, -45 * kDeg)], 4.72 - 0.05, 1e-9);   // world -x
  EXPECT_NEAR(r[beamAt(rear, 45 * kDeg)], 4.82 - 0.05, 1e-9);    // world -y
  EXPECT_NEAR(r[beamAt(rear, 135 * kDeg)], 9.95 - 4.72, 1e-9);   // world +x

  // Turned to +y: the front lidar is at (4.82, 5.28), looking at 135 deg.
  const Pose2 turned{5.0, 5.0, M_PI / 2};
  const auto ft = idealRanges(front, walls, {}, turned, 0.0);
  const auto rt = idealRanges(rear, walls, {}, turned, 0.0);
  EXPECT_NEAR(ft[beamAt(front, -45 * kDeg)], 9.95 - 5.28, 1e-9);  // world +y
  EXPECT_NEAR(ft[beamAt(front, 45 * kDeg)], 4.82 - 0.05, 1e-9);   // world -x
  EXPECT_NEAR(rt[beamAt(rear, -45 * kDeg)], 4.72 - 0.05, 1e-9);   // world -y
  EXPECT_NEAR(rt[beamAt(rear, 45 * kDeg)], 9.95 - 5.18, 1e-9);    // world +x
}

TEST(AmrRigTest, Each270DegreeFieldMissesItsCornerAndTogetherTheySeeAllAround) {
  const PlanarLidar front = amrFrontLidar(), rear = amrRearLidar();
  for (const PlanarLidar& l : {front, rear}) {
    EXPECT_EQ(l.beams, 541);
    EXPECT_NEAR(l.angle_min, -135 * kDeg, 1e-12);
    EXPECT_NEAR(l.angleMax(), 135 * kDeg, 1e-12);
    EXPECT_NEAR(l.angle_increment, 0.5 * kDeg, 1e-15);
    EXPECT_EQ(l.range_min, 0.05);
    EXPECT_EQ(l.range_max, 20.0);
  }
  // Every base-frame direction is within half a beam of one lidar's field,
  // and the directions into the robot's body (from the front lidar's corner
  // towards the rear one, and back) are outside the field of the lidar on
  // that corner.
  const auto sees = [](const PlanarLidar& l, double base_angle) {
    const double a = normalizeAngle(base_angle - l.mount.yaw);
    return a >= l.angle_min - 0.25 * kDeg && a <= l.angleMax() + 0.25 * kDeg;
  };
  for (int d = 0; d < 720; ++d) {
    const double a = d * 0.5 * kDeg;
    EXPECT_TRUE(sees(front, a) || sees(rear, a)) << d * 0.5 << " deg";
  }
  const double across = std::atan2(rear.mount.y - front.mount.y, rear.mount.x - front.mount.x);
  EXPECT_FALSE(sees(front, across));
  EXPECT_FALSE(sees(rear, across + M_PI));
  EXPECT_FALSE(sees(front, M_PI + M_PI / 4));  // straight into the body
  EXPECT_FALSE(sees(rear, M_PI / 4));
}

TEST(AmrRigTest, LidarsScanAtTheirOwnRatesAndNeverAtTheSameInstant) {
  const PlanarLidar front = amrFrontLidar(), rear = amrRearLidar();
  const int64_t tick = 10'000'000;  // the simulator's 10 ms
  std::vector<int64_t> front_stamps, rear_stamps;
  for (int64_t t = 0; t < 60'000'000'000; t += tick) {
    const bool f = front.schedule.scansAt(t), r = rear.schedule.scansAt(t);
    EXPECT_FALSE(f && r) << t;
    if (f) front_stamps.push_back(t);
    if (r) rear_stamps.push_back(t);
  }
  ASSERT_EQ(front_stamps.size(), 750u);  // 12.5 Hz for 60 s
  ASSERT_EQ(rear_stamps.size(), 600u);   // 10 Hz
  EXPECT_EQ(front_stamps[0], 30'000'000);
  EXPECT_EQ(rear_stamps[0], 60'000'000);
  for (std::size_t i = 1; i < front_stamps.size(); ++i) {
    EXPECT_EQ(front_stamps[i] - front_stamps[i - 1], 80'000'000);
  }
  for (std::size_t i = 1; i < rear_stamps.size(); ++i) {
    EXPECT_EQ(rear_stamps[i] - rear_stamps[i - 1], 100'000'000);
  }
  EXPECT_DOUBLE_EQ(front.schedule.rateHz(), 12.5);
  EXPECT_DOUBLE_EQ(rear.schedule.rateHz(), 10.0);
}

TEST(AmrRigTest, TheWarehouseLidarLooksForwardFromTheFrontEdgeTo25Metres) {
  const PlanarLidar l = amrWarehouseLidar({100'000'000, 70'000'000});
  EXPECT_EQ(l.topic, "/scan");
  EXPECT_EQ(l.beams, 541);
  EXPECT_NEAR(l.angle_min, -135 * kDeg, 1e-12);
  EXPECT_NEAR(l.angleMax(), 135 * kDeg, 1e-12);
  EXPECT_EQ(l.range_max, 25.0);
  EXPECT_DOUBLE_EQ(l.schedule.rateHz(), 10.0);
  // On the front edge of the body (0.64 m long), centred, looking ahead.
  EXPECT_EQ(l.mount.x, 0.32);
  EXPECT_EQ(l.mount.y, 0.0);
  EXPECT_EQ(l.mount.yaw, 0.0);
  const RayCaster walls(room());
  const auto r = idealRanges(l, walls, {}, {5.0, 5.0, 0.0}, 0.0);
  EXPECT_NEAR(r[beamAt(l, 0.0)], 9.95 - 5.32, 1e-9);        // ahead
  EXPECT_NEAR(r[beamAt(l, 90 * kDeg)], 9.95 - 5.0, 1e-9);   // left
  EXPECT_NEAR(r[beamAt(l, -90 * kDeg)], 5.0 - 0.05, 1e-9);  // right
  // It sees as far as its range allows and no further: in a 10 m room
  // nothing is out of range; in a 40 m one looking along it, +inf.
  const int n = 800;
  std::vector<int8_t> data(n * 200, 0);
  for (int i = 0; i < n; ++i) data[i] = data[199 * n + i] = 100;
  for (int j = 0; j < 200; ++j) data[j * n] = data[j * n + n - 1] = 100;
  const RayCaster hall(OccupancyGrid(n, 200, 0.05, {}, data));
  EXPECT_NEAR(idealRanges(l, hall, {}, {15.0, 5.0, 0.0}, 0.0)[beamAt(l, 0.0)], 39.95 - 15.32, 1e-9);
  EXPECT_TRUE(std::isinf(idealRanges(l, hall, {}, {10.0, 5.0, 0.0}, 0.0)[beamAt(l, 0.0)]));
}

TEST(AmrRigTest, TheMastLidarSitsWhereTheRingLidarIsAndScansWithIt) {
  const ScanSchedule schedule{2'000'000'000, 70'000'000};
  const RingLidar ring = amrRingLidar(schedule);
  const PlanarLidar mast = amrMastLidar(schedule);
  EXPECT_EQ(ring.frame, "velodyne");
  EXPECT_EQ(mast.frame, "laser");
  EXPECT_EQ(mast.mount.x, ring.mount.x);
  EXPECT_EQ(mast.mount.y, ring.mount.y);
  EXPECT_EQ(mast.mount.yaw, ring.mount.yaw);
  EXPECT_EQ(mast.height, 0.6);
  EXPECT_EQ(ring.height, 0.6);
  EXPECT_EQ(mast.beams, 720);
  EXPECT_NEAR(mast.angleMax(), 359.5 * kDeg, 1e-12);
  for (int64_t t = 0; t < 10'000'000'000; t += 10'000'000) {
    EXPECT_EQ(mast.schedule.scansAt(t), ring.schedule.scansAt(t)) << t;
  }
}

}  // namespace
}  // namespace pf::sim

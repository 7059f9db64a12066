#include "pf_localization/sim/sensor_block.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "pf_localization/sim/amr_rig.h"
#include "pf_localization/sim/planar_sensor.h"

namespace pf::sim {
namespace {

TEST(SensorBlockTest, ParsesNameAndTimes) {
  const SensorBlock b = parseSensorBlock("front:30:42.5");
  EXPECT_EQ(b.sensor, "front");
  EXPECT_EQ(b.from_ns, 30'000'000'000);
  EXPECT_EQ(b.to_ns, 42'500'000'000);
  EXPECT_FALSE(b.covers("front", 29'990'000'000));
  EXPECT_TRUE(b.covers("front", 30'000'000'000));
  EXPECT_TRUE(b.covers("front", 42'490'000'000));
  EXPECT_FALSE(b.covers("front", 42'500'000'000));
  EXPECT_FALSE(b.covers("rear", 35'000'000'000));
}

TEST(SensorBlockTest, RejectsMalformedBlocks) {
  for (const char* bad : {"front", "front:1", ":1:2", "front:1:2:3", "front:2:1", "front:1:1",
                          "front:-1:2", "front:a:2", "front:1:", "front:1:inf"}) {
    EXPECT_THROW(parseSensorBlock(bad), std::invalid_argument) << bad;
  }
}

// Scans of the AMR's front lidar through a run of 20 s with a wall 3 m away
// on every beam, covered from 5 to 8 s if `blocks` says so.
std::vector<std::vector<float>> frontScans(const std::vector<SensorBlock>& blocks) {
  PlanarSensor sensor(amrFrontLidar(), PlanarSensor::Model::kSafety, 42, blocks);
  const std::vector<double> ideal(sensor.lidar().beams, 3.0);
  std::vector<std::vector<float>> scans;
  for (int64_t t = 0; t < 20'000'000'000; t += 10'000'000) {
    if (sensor.lidar().schedule.scansAt(t)) scans.push_back(sensor.read(ideal, t));
  }
  return scans;
}

TEST(SensorBlockTest, ACoveredLidarReadsRangeMinThenAndOnlyThen) {
  const auto plain = frontScans({});
  const auto covered = frontScans({parseSensorBlock("front:5:8"), parseSensorBlock("rear:0:20")});
  ASSERT_EQ(plain.size(), 250u);
  ASSERT_EQ(covered.size(), plain.size());
  int covered_scans = 0;
  for (std::size_t k = 0; k < plain.size(); ++k) {
    const int64_t t = 30'000'000 + static_cast<int64_t>(k) * 80'000'000;
    if (t >= 5'000'000'000 && t < 8'000'000'000) {
      ++covered_scans;
      for (float r : covered[k]) ASSERT_EQ(r, 0.05f) << "scan " << k;
    } else {
      // Outside the block, the readings are the uncovered run's, bit for bit.
      ASSERT_EQ(covered[k], plain[k]) << "scan " << k;
    }
  }
  EXPECT_EQ(covered_scans, 37);  // stamps 5.07 .. 7.95 s, every 80 ms
}

}  // namespace
}  // namespace pf::sim

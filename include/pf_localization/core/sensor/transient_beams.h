// Beams that see something that has just moved in front of a robot standing
// still: they are dropped from the update, like beams with no reading.
//
// The likelihood field scores a beam by how near its end point lies to a
// mapped obstacle, so it has no word for "something is in the way": a
// person or a cart stepping up to a robot that stands still puts many end
// points in free space, and the filter and the scan fit move the pose
// towards whatever walls those end points happen to line up with. The beam
// model's "short" term (Thrun et al., "Probabilistic Robotics", 2005,
// sec. 6.3) has the idea for a single scan; here the evidence is stronger:
// from (nearly) the same place, a moment ago, the lidar saw further.
//
// The background is the scan taken where the robot came to stand: it starts
// over whenever the robot is more than kStillDistance or kStillAngle from
// there. Its end points are moved into each new scan's frame; a beam is
// masked when it ends kMargin short of everything the background saw within
// kBearingTolerance of it, unless it ends on the map where the robot is
// believed to be (OnMap). A beam short for kMaxMaskedScans scans in a row is
// taken as it is: what it sees has stayed (a pallet put down, a kidnapping).
// Each sensor of a group has its own background. docs/design.md, "Something
// steps up to a robot standing still", has the recording this came from.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

class TransientBeams {
 public:
  // m: a beam this much shorter than its background saw something move in.
  // Well above what a standing robot's beams vary by (a few centimetres on
  // the CARMEN logs and the Neato) and what creeping kStillDistance changes.
  static constexpr double kMargin = 0.2;
  // m, rad: further than this from where the background was taken, the
  // robot's own motion changes its beams, and the background starts over.
  static constexpr double kStillDistance = 0.05;
  static constexpr double kStillAngle = 1.0 * M_PI / 180.0;
  // rad: a beam is compared with what the background saw this far either
  // side of it, for the odometry's error in the turn and depth edges.
  static constexpr double kBearingTolerance = 1.0 * M_PI / 180.0;
  // Scans a beam stays masked at most, in a row: a second at 5 Hz.
  static constexpr int kMaxMaskedScans = 5;

  /// Whether an end point (x, y in the robot's frame at the update) lies on
  /// the map where the robot is believed to be: such a beam is not masked,
  /// whatever moved, the map has it.
  using OnMap = std::function<bool(double x, double y)>;

  /// The scans of `scans` at odometry `odom`, with the beams that see
  /// something that moved in set to "no reading". Returns `scans` itself
  /// when no beam is masked; else a group over *storage, which holds the
  /// masked copies and must outlive it. Malformed scans and a non-finite
  /// odometry pass through and leave the background as it is. `on_map` may
  /// be empty (no map, no estimate yet).
  ScanGroup mask(const Pose2& odom, const ScanGroup& scans, const OnMap& on_map,
                 std::vector<LaserScan>* storage);

  /// Beams masked by the last mask() call, over all its scans.
  int masked() const { return masked_; }

 private:
  struct Background {
    std::vector<float> ranges;           // of each beam; inf: no reading
    std::vector<std::uint8_t> in_a_row;  // scans each beam has been masked in a row
    std::vector<float> seen;             // scratch: the ranges moved into the latest scan's frame
    Pose2 at;  // where the background was taken: the sensor's pose in the odometry frame
    // The layout of the scans it came from: a scan of another layout starts it over.
    double angle_min = 0.0;
    double angle_increment = 0.0;
    Pose2 sensor_pose;

    bool sameLayout(const LaserScan& scan) const;
  };
  // Masks the beams of `scan` taken at `at` against `bg` (starting it over
  // when the robot moved or the sensor's layout changed) into *masked;
  // returns the number masked.
  static int maskScan(const LaserScan& scan, const Pose2& at, const OnMap& on_map, Background* bg,
                      std::vector<float>* masked);

  std::vector<Background> backgrounds_;  // one per sensor of the group
  int masked_ = 0;
};

}  // namespace pf

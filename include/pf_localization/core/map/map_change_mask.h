// Beams that see a change of the map, left out while the tracked pose still
// explains the rest of the scan.
//
// A map is out of date within weeks: furniture moves, a wall gets cabinets, a
// door is closed. The likelihood field then scores the beams that see the
// change as misfits at the right pose, pulls the pose towards whatever walls
// their end points line up with (a cabinet's face taken for the wall behind
// it), and the fit that drops reads as "lost" to recovery and the verdict.
// So, per scan, the beams are judged at the pose the filter tracks (the last
// estimate moved by the odometry since: MapEvidence). When the scan agrees
// with the map there, as a scan at the right pose does however much of it the
// changes hide (at least kMinEndingOnMap of the beams end on a mapped
// obstacle, and at most kMaxContradicting pass through one into the open or
// leave the map), the beams that disagree are evidence about the map, not
// against the pose: they are masked like beams with no reading, and the
// weighing, the estimate, the scan fit, the verdict and recovery see the
// rest. Otherwise nothing is masked: a wrong pose is for those to find.
//
// Only the caller knows when there is a tracked pose to judge from (an
// update since an initialisation, a place told apart from its look-alikes,
// a verdict other than lost); it calls mask() then. See docs/design.md, "A
// map out of date is not a wrong pose".
#pragma once

#include <vector>

#include "pf_localization/core/map/map_evidence.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

class MapChangeMask {
 public:
  /// At least this share of a scan's beams ends on a mapped obstacle at a
  /// pose the scan agrees with. A third of the beams hidden by people and a
  /// tenth by changes of the map still leave more than half.
  static constexpr double kMinEndingOnMap = 0.4;
  /// At most this share passes through a mapped obstacle into the open or
  /// ends off the map there: a door opened since the map was made lets a few
  /// through; at a wrong pose a third to a half do.
  static constexpr double kMaxContradicting = 0.2;
  /// Of which at most this share leaves the map: a building's outline
  /// changes least, and a scan that runs past it was placed wrong.
  static constexpr double kMaxOffMap = 0.05;
  /// And at least this share is left, clear of the map's obstacles on its way
  /// and ending on one: what the filter goes on with.
  static constexpr double kMinKept = 0.2;

  /// `scans`, with the beams that see a change of the map from the robot pose
  /// `robot` masked when the scans agree with the map there (above). Returns
  /// `scans` itself when nothing is masked; else a group over *storage, which
  /// holds the masked copies and must outlive it.
  ScanGroup mask(const MapEvidence& evidence, const ScanGroup& scans, const Pose2& robot,
                 std::vector<LaserScan>* storage);
  /// Forgets the last judgement (a scan not judged).
  void clear() { *this = MapChangeMask(); }

  /// The last judgement: what its beams said; how many the last mask() masked.
  const EvidenceCounts& counts() const { return counts_; }
  int masked() const { return masked_; }
  /// Whether the last judged scans agreed with the map (their changes masked).
  bool agrees() const { return agrees_; }
  /// The share of the last judged beams that saw a change of the map (0
  /// when the scans did not agree with the map: nothing was masked).
  double changedShare() const;

 private:
  // Judges `scans` from `robot` into evidence_ and counts_; whether they agree.
  bool judge(const MapEvidence& evidence, const ScanGroup& scans, const Pose2& robot);

  EvidenceCounts counts_;
  bool agrees_ = false;  // the last judged scans agreed with the map
  int masked_ = 0;
  std::vector<std::vector<BeamEvidence>> evidence_;  // of the last judged scans, per beam
};

}  // namespace pf

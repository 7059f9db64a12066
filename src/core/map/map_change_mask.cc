#include "pf_localization/core/map/map_change_mask.h"

#include <limits>

namespace pf {
namespace {

// Whether a beam sees a change of the map (masked when the scan agrees with
// the map elsewhere). One that passes a mapped
// obstacle and ends on another (a removed object, or a blurred wall of a
// real map seen through) fits where it ends, and is kept.
bool seesChange(BeamEvidence e) {
  return e == BeamEvidence::kShortOfMap || e == BeamEvidence::kThroughOntoAdded ||
         e == BeamEvidence::kThroughIntoOpen || e == BeamEvidence::kOffMap;
}

}  // namespace

bool MapChangeMask::judge(const MapEvidence& evidence, const ScanGroup& scans, const Pose2& robot) {
  counts_ = EvidenceCounts();
  evidence_.resize(scans.size());
  for (std::size_t s = 0; s < scans.size(); ++s) {
    counts_ += evidence.judge(scans[s], robot, &evidence_[s]);
  }
  const double beams = static_cast<double>(counts_.beams());
  // People and objects the map lacks say nothing of the pose: the scan is
  // judged by the beams that reach the map's obstacles or pass them.
  const double judged = beams - static_cast<double>(counts_.short_of_map);
  return beams > 0.0 && static_cast<double>(counts_.endingOnMap()) >= kMinEndingOnMap * judged &&
         counts_.contradicting() <= kMaxContradicting * judged &&
         static_cast<double>(counts_.off_map) <= kMaxOffMap * judged &&
         static_cast<double>(counts_.on_map) >= kMinKept * beams;
}

ScanGroup MapChangeMask::mask(const MapEvidence& evidence, const ScanGroup& scans,
                              const Pose2& robot, std::vector<LaserScan>* storage) {
  masked_ = 0;
  agrees_ = judge(evidence, scans, robot);
  if (!agrees_) return scans;
  storage->assign(scans.begin(), scans.end());
  for (std::size_t s = 0; s < scans.size(); ++s) {
    std::vector<float>& ranges = (*storage)[s].ranges;
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      if (!seesChange(evidence_[s][i]) ||
          !isReading(ranges[i], (*storage)[s].range_min, (*storage)[s].range_max)) {
        continue;
      }
      ranges[i] = std::numeric_limits<float>::quiet_NaN();
      ++masked_;
    }
  }
  if (masked_ == 0) return scans;
  return ScanGroup(*storage);
}

double MapChangeMask::changedShare() const {
  const std::size_t beams = counts_.beams();
  if (!agrees_ || beams == 0) return 0.0;
  const std::size_t changed = counts_.short_of_map + counts_.through_into_open + counts_.off_map;
  return static_cast<double>(changed) / static_cast<double>(beams);
}

}  // namespace pf

#include "pf_localization/core/sensor/scan_group.h"

#include <utility>

namespace pf {

std::vector<PreparedScan> prepareScans(const SensorModel& model, const ScanGroup& scans) {
  std::vector<PreparedScan> out;
  out.reserve(scans.size());
  for (const LaserScan& scan : scans) out.push_back(model.prepare(scan));
  return out;
}

std::vector<PreparedScan> prepareScans(const SensorModel& model, const ScanGroup& scans,
                                       int max_beams) {
  std::vector<PreparedScan> out;
  out.reserve(scans.size());
  for (const LaserScan& scan : scans) out.push_back(model.prepare(scan, max_beams));
  return out;
}

PreparedScan joinedEndPoints(std::vector<PreparedScan> scans) {
  if (scans.size() == 1) return std::move(scans.front());
  PreparedScan out;
  out.x.reserve(beamCount(scans));
  out.y.reserve(beamCount(scans));
  for (const PreparedScan& s : scans) {
    out.x.insert(out.x.end(), s.x.begin(), s.x.end());
    out.y.insert(out.y.end(), s.y.begin(), s.y.end());
    out.range.insert(out.range.end(), s.range.begin(), s.range.end());
    out.angle.insert(out.angle.end(), s.angle.begin(), s.angle.end());
    out.dropped += s.dropped;
  }
  return out;
}

std::size_t beamCount(const std::vector<PreparedScan>& scans) {
  std::size_t n = 0;
  for (const PreparedScan& s : scans) n += s.size();
  return n;
}

int droppedBeams(const std::vector<PreparedScan>& scans) {
  int n = 0;
  for (const PreparedScan& s : scans) n += s.dropped;
  return n;
}

double hitFraction(const SensorModel& model, const std::vector<PreparedScan>& scans,
                   const Pose2& pose, double distance) {
  if (scans.size() == 1) return model.hitFraction(scans.front(), pose, distance);
  const std::size_t beams = beamCount(scans);
  if (beams == 0) return 0.0;
  double hits = 0.0;
  for (const PreparedScan& s : scans) {
    hits += model.hitFraction(s, pose, distance) * static_cast<double>(s.size());
  }
  return hits / static_cast<double>(beams);
}

}  // namespace pf

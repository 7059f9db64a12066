#include "pf_localization/core/hypotheses.h"

#include <algorithm>
#include <cmath>

#include "pf_localization/core/look_alikes.h"

namespace pf {

Hypotheses hypothesesOf(const PoseEstimate& estimate, double rival_weight_ratio,
                        std::size_t max_listed) {
  Hypotheses out;
  double total = 0.0;
  for (const Cluster& c : estimate.clusters) total += c.weight;
  if (estimate.clusters.empty() || !(total > 0.0)) return out;
  const Cluster& heaviest = estimate.clusters.front();
  for (const Cluster& c : estimate.clusters) {
    const double share = c.weight / total;
    if (&c != &heaviest && !isRival(c, heaviest, rival_weight_ratio) &&
        share < kMinHypothesisShare) {
      continue;
    }
    ++out.count;
    if (out.listed.size() < max_listed)
      out.listed.push_back({c.mean, share, c.covariance, c.count});
  }
  return out;
}

void addLookAlikes(const std::vector<Pose2>& places, Hypotheses* hypotheses) {
  if (hypotheses->listed.empty()) return;
  const Eigen::Matrix3d covariance = hypotheses->listed.front().covariance;
  for (const Pose2& place : places) {
    const bool held =
        std::any_of(hypotheses->listed.begin(), hypotheses->listed.end(), [&](const Hypothesis& h) {
          return std::hypot(h.pose.x - place.x, h.pose.y - place.y) < LookAlikes::kMinShift;
        });
    if (held) continue;
    ++hypotheses->count;
    if (hypotheses->listed.size() < kMaxListedHypotheses) {
      hypotheses->listed.push_back({place, 0.0, covariance, 0});
    }
  }
}

}  // namespace pf

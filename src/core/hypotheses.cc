#include "pf_localization/core/hypotheses.h"

#include <algorithm>
#include <cmath>
#include <vector>

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

void addLookAlikes(std::vector<LookAlikePlace> places, Hypotheses* hypotheses) {
  if (hypotheses->listed.empty()) return;
  std::stable_sort(places.begin(), places.end(),
                   [](const LookAlikePlace& a, const LookAlikePlace& b) { return a.fit > b.fit; });
  const Eigen::Matrix3d covariance = hypotheses->listed.front().covariance;
  std::vector<Pose2> taken;  // the cloud's hypotheses, then the places counted
  for (const Hypothesis& h : hypotheses->listed) taken.push_back(h.pose);
  for (const LookAlikePlace& place : places) {
    const Pose2& p = place.pose;
    const bool held = std::any_of(taken.begin(), taken.end(), [&](const Pose2& q) {
      return std::hypot(q.x - p.x, q.y - p.y) < LookAlikes::kMinShift;
    });
    if (held) continue;
    taken.push_back(p);
    ++hypotheses->count;
    if (hypotheses->listed.size() < kMaxListedHypotheses) {
      hypotheses->listed.push_back({p, 0.0, covariance, 0});
    }
  }
}

Eigen::Matrix3d lookAlikeCovariance(const Pose2& estimate, const Eigen::Matrix3d& covariance,
                                    double fit, std::vector<LookAlikePlace> places) {
  if (!std::isfinite(fit)) return covariance;
  std::stable_sort(places.begin(), places.end(),
                   [](const LookAlikePlace& a, const LookAlikePlace& b) { return a.fit > b.fit; });
  // Log-likelihoods relative to the estimate's, then to the largest, so
  // that a far better look-alike does not overflow the exponential.
  std::vector<Eigen::Vector3d> offsets{Eigen::Vector3d::Zero()};
  std::vector<double> log_ratio{0.0};
  std::vector<Pose2> taken{estimate};
  for (const LookAlikePlace& place : places) {
    const Pose2& p = place.pose;
    const bool same = std::any_of(taken.begin(), taken.end(), [&](const Pose2& q) {
      return std::hypot(q.x - p.x, q.y - p.y) < LookAlikes::kMinShift;
    });
    if (same || !std::isfinite(place.fit)) continue;
    taken.push_back(p);
    offsets.emplace_back(p.x - estimate.x, p.y - estimate.y, angleDiff(p.yaw, estimate.yaw));
    log_ratio.push_back(place.fit - fit);
  }
  const double top = *std::max_element(log_ratio.begin(), log_ratio.end());
  double total = 0.0;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < offsets.size(); ++k) {
    const double w = std::exp(log_ratio[k] - top);
    total += w;
    spread += w * offsets[k] * offsets[k].transpose();
  }
  return covariance + spread / total;
}

}  // namespace pf

#include "pf_localization/core/estimate/hypotheses.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "pf_localization/core/recovery/look_alikes.h"

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

namespace {

// `places`, best fit first, less those within LookAlikes::kMinShift of one
// of `taken` or of a better fitting place: each place once.
std::vector<LookAlikePlace> distinctPlaces(std::vector<LookAlikePlace> places,
                                           std::vector<Pose2> taken) {
  std::stable_sort(places.begin(), places.end(),
                   [](const LookAlikePlace& a, const LookAlikePlace& b) { return a.fit > b.fit; });
  std::vector<LookAlikePlace> out;
  for (const LookAlikePlace& place : places) {
    const Pose2& p = place.pose;
    const bool seen = std::any_of(taken.begin(), taken.end(), [&](const Pose2& q) {
      return std::hypot(q.x - p.x, q.y - p.y) < LookAlikes::kMinShift;
    });
    if (seen) continue;
    taken.push_back(p);
    out.push_back(place);
  }
  return out;
}

}  // namespace

void addLookAlikes(std::vector<LookAlikePlace> places, Hypotheses* hypotheses) {
  if (hypotheses->listed.empty()) return;
  const Eigen::Matrix3d covariance = hypotheses->listed.front().covariance;
  std::vector<Pose2> held;
  for (const Hypothesis& h : hypotheses->listed) held.push_back(h.pose);
  for (const LookAlikePlace& place : distinctPlaces(std::move(places), std::move(held))) {
    ++hypotheses->count;
    if (hypotheses->listed.size() < kMaxListedHypotheses) {
      hypotheses->listed.push_back({place.pose, 0.0, covariance, 0});
    }
  }
}

Eigen::Matrix3d lookAlikeCovariance(const Pose2& estimate, const Eigen::Matrix3d& covariance,
                                    double fit, std::vector<LookAlikePlace> places) {
  if (!std::isfinite(fit)) return covariance;
  // Log-likelihoods relative to the estimate's, then to the largest, so
  // that a far better look-alike does not overflow the exponential.
  std::vector<Eigen::Vector3d> offsets{Eigen::Vector3d::Zero()};
  std::vector<double> log_ratio{0.0};
  for (const LookAlikePlace& place : distinctPlaces(std::move(places), {estimate})) {
    if (!std::isfinite(place.fit)) continue;
    const Pose2& p = place.pose;
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

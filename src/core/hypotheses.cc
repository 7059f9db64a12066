#include "pf_localization/core/hypotheses.h"

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

}  // namespace pf

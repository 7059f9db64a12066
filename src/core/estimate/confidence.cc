#include "pf_localization/core/estimate/confidence.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/util/parameter_table.h"

namespace pf {

const char* toString(LocalizationState state) {
  switch (state) {
    case LocalizationState::kLocalized:
      return "localized";
    case LocalizationState::kUncertain:
      return "uncertain";
    default:
      return "lost";
  }
}

void validate(const ConfidenceParams& p) {
  requireParameter(p.hit_distance > 0.0 && std::isfinite(p.hit_distance), "confidence_hit_distance",
                   "> 0", p.hit_distance);
  requireParameter(p.lost_hit_fraction >= 0.0 && p.lost_hit_fraction <= 1.0,
                   "confidence_lost_hit_fraction", "in [0, 1]", p.lost_hit_fraction);
  requireParameter(
      p.localized_hit_fraction >= p.lost_hit_fraction && p.localized_hit_fraction <= 1.0,
      "confidence_localized_hit_fraction", "in [confidence_lost_hit_fraction, 1]",
      p.localized_hit_fraction);
  requireParameter(p.localized_std_xy > 0.0, "confidence_localized_std_xy", "> 0",
                   p.localized_std_xy);
  requireParameter(p.localized_std_yaw > 0.0, "confidence_localized_std_yaw", "> 0",
                   p.localized_std_yaw);
  requireParameter(p.rival_weight_ratio > 0.0 && p.rival_weight_ratio <= 1.0,
                   "confidence_rival_weight_ratio", "in (0, 1]", p.rival_weight_ratio);
  requireParameter(p.jump_distance > 0.0 && std::isfinite(p.jump_distance),
                   "confidence_jump_distance", "> 0", p.jump_distance);
  requireParameter(p.jump_yaw > 0.0 && std::isfinite(p.jump_yaw), "confidence_jump_yaw", "> 0",
                   p.jump_yaw);
  requireParameter(p.settle_updates >= 0, "confidence_settle_updates", ">= 0", p.settle_updates);
}

Confidence assessConfidence(const ParticleSet& particles, const PoseEstimate& estimate,
                            double hit_fraction, const ConfidenceParams& params, int threads) {
  Confidence c;
  c.hit_fraction = hit_fraction;
  if (estimate.clusters.empty()) {
    c.reason = "no particles";
    return c;
  }
  const Cluster& first = estimate.clusters.front();
  c.std_x = std::sqrt(first.covariance(0, 0));
  c.std_y = std::sqrt(first.covariance(1, 1));
  c.std_yaw = std::sqrt(first.covariance(2, 2));
  for (std::size_t k = 1; k < estimate.clusters.size(); ++k) {
    // Every rival is listed on pf_hypotheses (hypothesesOf).
    c.rivals += isRival(estimate.clusters[k], first, params.rival_weight_ratio) ? 1 : 0;
  }
  c.covariance = first.covariance;
  if (c.rivals > 0) {
    c.covariance = summarize(particles, threads).covariance;
  }

  std::ostringstream why;
  why << std::fixed << std::setprecision(0);
  if (hit_fraction < params.lost_hit_fraction) {
    c.state = LocalizationState::kLost;
    why << "only " << 100.0 * hit_fraction << " % of the beams fit the map at the estimate";
  } else if (c.rivals > 0) {
    c.state = LocalizationState::kUncertain;
    why << c.rivals << " rival hypothes" << (c.rivals == 1 ? "is" : "es") << " elsewhere";
  } else if (hit_fraction < params.localized_hit_fraction) {
    c.state = LocalizationState::kUncertain;
    why << "only " << 100.0 * hit_fraction << " % of the beams fit the map at the estimate";
  } else if (std::max(c.std_x, c.std_y) > params.localized_std_xy ||
             c.std_yaw > params.localized_std_yaw) {
    c.state = LocalizationState::kUncertain;
    why << "the particles are spread (std " << std::setprecision(2) << std::max(c.std_x, c.std_y)
        << " m, " << std::setprecision(0) << c.std_yaw * 180.0 / M_PI << " deg)";
  } else {
    c.state = LocalizationState::kLocalized;
    why << 100.0 * hit_fraction << " % of the beams fit, one hypothesis";
  }
  c.reason = why.str();
  return c;
}

void holdAfterJump(const Pose2& predicted, const Pose2& estimate, const ConfidenceParams& params,
                   int* settle_left, Confidence* confidence) {
  const Pose2 d = between(predicted, estimate);
  const double jump = std::hypot(d.x, d.y);
  if (jump > params.jump_distance || std::fabs(d.yaw) > params.jump_yaw) {
    *settle_left = params.settle_updates;
  } else if (*settle_left > 0) {
    --*settle_left;
  }
  if (*settle_left > 0 && confidence->state == LocalizationState::kLocalized) {
    confidence->state = LocalizationState::kUncertain;
    std::ostringstream why;
    why << "the estimate jumped recently: " << *settle_left << " more update"
        << (*settle_left == 1 ? "" : "s") << " to confirm it";
    confidence->reason = why.str();
  }
}

}  // namespace pf

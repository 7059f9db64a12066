#include "pf_localization/core/confidence_tracker.h"

#include <string>

#include "pf_localization/core/hypotheses.h"
#include "pf_localization/core/scan_refiner.h"

namespace pf {

void ConfidenceTracker::restart(const Eigen::Matrix3d& covariance) {
  confidence_ = Confidence();
  confidence_.state = LocalizationState::kUncertain;
  fit_state_ = confidence_.state;
  confidence_.reason = "no scan since the initialisation";
  confidence_.covariance = covariance;
  settle_left_ = 0;
}

void ConfidenceTracker::assess(const ParticleSet& particles, const PoseEstimate& estimate,
                               double hit_fraction, const ConfidenceParams& params, int threads) {
  confidence_ = assessConfidence(particles, estimate, hit_fraction, params, threads);
  fit_state_ = confidence_.state;
}

void ConfidenceTracker::holdAfterJump(const std::optional<Pose2>& predicted, const Pose2& estimate,
                                      const ConfidenceParams& params) {
  if (predicted) pf::holdAfterJump(*predicted, estimate, params, &settle_left_, &confidence_);
}

void ConfidenceTracker::holdWhileAmbiguous(std::size_t places, std::size_t look_alikes) {
  if (confidence_.state != LocalizationState::kLocalized) return;
  if (places > 1) {
    confidence_.reason =
        std::to_string(places - 1) + " other place" + (places > 2 ? "s" : "") + " with at least " +
        std::to_string(static_cast<int>(100 * kMinHypothesisShare)) + " % of the weight";
  } else if (look_alikes > 0) {
    confidence_.reason = "the scan fits " + std::to_string(look_alikes) + " look-alike place" +
                         (look_alikes > 1 ? "s" : "") + " of the map as well";
  } else {
    return;
  }
  confidence_.state = LocalizationState::kUncertain;
}

void ConfidenceTracker::addFit(const Eigen::Matrix3d& fit_covariance) {
  confidence_.covariance = confidence_.rivals > 0
                               ? coveringCovariance(fit_covariance, confidence_.covariance)
                               : fusedCovariance(fit_covariance, confidence_.covariance);
}

void ConfidenceTracker::demoteAfterLowFit(int low_fit_updates, int patience) {
  if (confidence_.state == LocalizationState::kLocalized && low_fit_updates > patience) {
    confidence_.state = LocalizationState::kUncertain;
    confidence_.reason = "the scans have fitted worse than usual for " +
                         std::to_string(low_fit_updates) + " updates";
  }
}

}  // namespace pf

#include "pf_localization/core/estimate/confidence_tracker.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/estimate/scan_refiner.h"
#include "pf_localization/core/filter/view_share.h"

namespace pf {

namespace {

// chi-square with 3 degrees of freedom at 99.9 %: a jump this far (squared,
// in the standard deviations of the last published spread and the cloud's
// together) left both.
constexpr double kJumpGate = 16.27;

}  // namespace

void ConfidenceTracker::restart(const Eigen::Matrix3d& covariance, bool place_given) {
  confidence_ = Confidence();
  confidence_.state = LocalizationState::kUncertain;
  fit_state_ = confidence_.state;
  confidence_.reason = "no scan since the initialisation";
  confidence_.covariance = covariance;
  settle_left_ = 0;
  place_known_ = place_given;
  covers_places_ = false;
}

void ConfidenceTracker::assess(const ParticleSet& particles, const PoseEstimate& estimate,
                               double hit_fraction, const ConfidenceParams& params, int threads) {
  previous_covariance_ = confidence_.covariance;
  confidence_ = assessConfidence(particles, estimate, hit_fraction, params, threads);
  fit_state_ = confidence_.state;
  covers_places_ = false;
}

void ConfidenceTracker::holdAfterJump(const std::optional<Pose2>& predicted, const Pose2& estimate,
                                      const ConfidenceParams& params) {
  if (!predicted) return;
  pf::holdAfterJump(*predicted, estimate, params, &settle_left_, &confidence_);
  // A jump as far as a look-alike can be (LookAlikes::kMinShift, or a turn
  // towards a half-turn twin) and beyond both the last published spread and
  // the cloud's: the scans alone chose where the cloud went. Within them (a
  // cloud long along a corridor, say) the track had not ruled it out.
  const Eigen::Vector3d d = poseDifference(estimate, *predicted);
  const bool far = d.head<2>().norm() >= LookAlikes::kMinShift || std::fabs(d(2)) > 0.5 * M_PI;
  if (far && squaredMahalanobis(d, previous_covariance_ + confidence_.covariance) > kJumpGate) {
    place_known_ = false;
  }
}

void ConfidenceTracker::holdWhileAmbiguous(std::size_t places, std::size_t look_alikes) {
  if (fit_state_ != LocalizationState::kLost && places <= 1 && look_alikes == 0) {
    place_known_ = true;
  }
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

void ConfidenceTracker::coverLookAlikes(const Pose2& estimate, double fit,
                                        const std::vector<LookAlikePlace>& places) {
  if (place_known_ || places.empty()) return;
  confidence_.covariance = lookAlikeCovariance(estimate, confidence_.covariance, fit, places);
  covers_places_ = true;
}

void ConfidenceTracker::addFit(const Eigen::Matrix3d& fit_covariance) {
  confidence_.covariance = confidence_.rivals > 0 || covers_places_
                               ? coveringCovariance(fit_covariance, confidence_.covariance)
                               : fusedCovariance(fit_covariance, confidence_.covariance);
}

void ConfidenceTracker::demoteAfterLowFit(double low_fit_views, int patience) {
  if (confidence_.state == LocalizationState::kLocalized &&
      moreViewsThan(low_fit_views, patience)) {
    confidence_.state = LocalizationState::kUncertain;
    char views[32];
    std::snprintf(views, sizeof(views), "%.3g", low_fit_views);
    confidence_.reason =
        std::string("the scans have fitted worse than usual for ") + views + " views";
  }
}

}  // namespace pf

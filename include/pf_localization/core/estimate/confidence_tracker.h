// The filter's verdict over time: the confidence of each update
// (assessConfidence), held back after a jump of the estimate until it is
// confirmed (holdAfterJump), and demoted from "localized" while the scans
// have fitted worse than usual for longer than recovery's patience: a cloud
// settled on a wrong place that fits most beams looks just like a right one,
// and says so while recovery waits. See docs/design.md, "Recovery waits while
// localized".
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/recovery/look_alikes.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

class ConfidenceTracker {
 public:
  /// After an initialisation: "uncertain" with `covariance` (the new
  /// cloud's), no jump pending. `place_given`: the cloud was drawn around a
  /// given pose, which tells the robot's place from its look-alikes.
  void restart(const Eigen::Matrix3d& covariance, bool place_given = true);

  /// The verdict on this update's weighted cloud, `hit_fraction` of the
  /// scan's beams hitting an obstacle from `estimate`.
  void assess(const ParticleSet& particles, const PoseEstimate& estimate, double hit_fraction,
              const ConfidenceParams& params, int threads = 1);
  /// The history check (holdAfterJump) against `predicted`, the previous
  /// estimate moved by the odometry since; nothing without one. After a
  /// jump as far as a look-alike can be and beyond the last published
  /// spread, the scans alone chose the place: it is no longer told apart
  /// from its look-alikes (coverLookAlikes).
  void holdAfterJump(const std::optional<Pose2>& predicted, const Pose2& estimate,
                     const ConfidenceParams& params);
  /// "localized" becomes "uncertain" while the cloud holds more than one
  /// place (`places`, hypothesesOf's count): the published verdict never
  /// says "localized" beside a second place on pf_hypotheses. Nor while the
  /// scan fits `look_alikes` other places of the map as well (look_alikes.h).
  /// A scan that fits no look-alike as well while the cloud holds one place
  /// tells the place apart from its look-alikes, until the next jump.
  void holdWhileAmbiguous(std::size_t places, std::size_t look_alikes = 0);
  /// While the place has not been told apart from its look-alikes (after a
  /// global initialisation or a jump, until such a scan), the published
  /// covariance covers the look-alike `places` the scans (log-likelihood
  /// `fit` at `estimate`) fit as well (lookAlikeCovariance): the cloud then
  /// sits at one of them by chance, not by evidence. Once told apart, the
  /// track since rules them out, and the cloud's covariance stands.
  void coverLookAlikes(const Pose2& estimate, double fit,
                       const std::vector<LookAlikePlace>& places);
  /// Adds a scan fit's covariance to the published one (fusedCovariance),
  /// unless that is the whole cloud's for rival hypotheses or covers
  /// look-alike places, which a fit of the best one cannot narrow: then it
  /// widens it to cover the fit's too.
  void addFit(const Eigen::Matrix3d& fit_covariance);
  /// "localized" becomes "uncertain" when the consecutive updates with a
  /// fit below recovery's trigger brought more than `patience` new views
  /// (view_share.h; with the default thresholds, one each).
  void demoteAfterLowFit(double low_fit_views, int patience);

  const Confidence& confidence() const { return confidence_; }
  /// This update's verdict from its scan alone, before holdAfterJump and the
  /// low-fit demotion: what tempering and recovery follow.
  LocalizationState fitState() const { return fit_state_; }
  /// Whether the place is told apart from its look-alikes (holdWhileAmbiguous).
  bool placeKnown() const { return place_known_; }
  /// Whether a jump of the estimate is still to be confirmed (holdAfterJump).
  bool settling() const { return settle_left_ > 0; }

 private:
  Confidence confidence_;
  LocalizationState fit_state_ = LocalizationState::kLost;
  int settle_left_ = 0;  // updates until a jumped estimate may be localized
  Eigen::Matrix3d previous_covariance_ = Eigen::Matrix3d::Zero();  // the last one published
  bool place_known_ = false;    // the place is told apart from its look-alikes
  bool covers_places_ = false;  // this update's covariance covers look-alike places
};

}  // namespace pf

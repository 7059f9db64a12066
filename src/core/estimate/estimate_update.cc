#include "pf_localization/core/estimate/estimate_update.h"

#include <cmath>
#include <utility>

namespace pf {

void EstimateUpdate::setMap(std::vector<MapSymmetry> symmetries) {
  look_alikes_.setSymmetries(std::move(symmetries));
  look_alike_places_.clear();
  refinement_.reset();  // fitted to the old map
}

void EstimateUpdate::restart(const PoseEstimate& estimate, bool place_given) {
  estimate_ = estimate;
  refinement_.reset();
  confidence_.restart(estimate_.covariance, place_given);
  look_alikes_.restart();
  look_alike_places_.clear();
}

Judgement EstimateUpdate::judge(const SensorModel& model, const ParticleSet& particles,
                                const std::vector<PreparedScan>& fitting,
                                const std::vector<PreparedScan>& steady,
                                const std::optional<Pose2>& predicted, const MapEvidence* evidence,
                                const ParticleFilterParams& params, int threads) {
  // The estimate comes from the weighted cloud, before resampling: resampling
  // only adds noise, and the random particles recovery injects must not count.
  estimate_ = estimatePose(particles, params.clusters, threads);
  confidence_.assess(particles, estimate_,
                     hitFraction(model, fitting, estimate_.pose, params.confidence.hit_distance),
                     params.confidence, threads);
  // Tempering and recovery follow the evidence of this scan (fitState());
  // only the published verdict waits for a jumped estimate to be confirmed.
  confidence_.holdAfterJump(predicted, estimate_.pose, params.confidence);
  Judgement out;
  out.places = hypothesesOf(estimate_, params.confidence.rival_weight_ratio, 0).count;
  LookAlikeView view = look_alikes_.judge(model, steady, estimate_.pose, evidence);
  confidence_.holdWhileAmbiguous(out.places, view.as_good);
  listLookAlikes(model, steady, view, out.places, params.confidence.rival_weight_ratio);
  places_ = out.places;
  confidence_.coverLookAlikes(estimate_.pose, view.fit, look_alike_places_);
  out.report.look_alikes = view.as_good;
  out.report.look_alikes_better = view.better.size();
  out.better = std::move(view.better);
  return out;
}

void EstimateUpdate::listLookAlikes(const SensorModel& model,
                                    const std::vector<PreparedScan>& scans,
                                    const LookAlikeView& view, std::size_t places,
                                    double rival_weight_ratio) {
  look_alike_places_ = view.places;
  if (places < 2) return;
  // A cloud spread over several places may hold none at the true place but
  // one a rack bay along it: the look-alikes of each are places too.
  const Hypotheses held = hypothesesOf(estimate_, rival_weight_ratio);
  std::vector<Pose2> others;
  for (std::size_t i = 1; i < held.listed.size(); ++i) others.push_back(held.listed[i].pose);
  const std::vector<LookAlikePlace> around =
      look_alikes_.placesAround(model, scans, others, view.fit - LookAlikes::kAsGoodMargin);
  look_alike_places_.insert(look_alike_places_.end(), around.begin(), around.end());
}

ScanRefinement EstimateUpdate::refine(const SensorModel& model, const ScanGroup& scans,
                                      const Pose2& odom, const std::optional<Pose2>& predicted,
                                      const ParticleFilterParams& params) {
  const ScanRefinement fit = refinement_.atUpdate(
      model, scans, odom, predicted, confidence_.confidence().state, params, &estimate_);
  if (fit.accepted) confidence_.addFit(fit.covariance);
  return fit;
}

bool EstimateUpdate::fitPinsAlongTrack(const ScanRefinement& fit, double margin) const {
  if (!fit.accepted) return true;
  const Eigen::Vector3d u(std::cos(estimate_.pose.yaw), std::sin(estimate_.pose.yaw), 0.0);
  return u.dot(fitInformation(fit.covariance).information * u) * margin * margin >= 1.0;
}

ScanRefinement EstimateUpdate::refitBetweenUpdates(const SensorModel& model, const ScanGroup& scans,
                                                   const Pose2& odom, const Pose2& odom_at_update,
                                                   const ParticleFilterParams& params) {
  return refinement_.betweenUpdates(model, scans, odom, odom_at_update, estimate_,
                                    confidence_.confidence().state, params);
}

bool EstimateUpdate::judgesBeams() const {
  return confidence_.placeKnown() && !confidence_.settling() &&
         confidence_.confidence().state != LocalizationState::kLost && places_ <= 1;
}

Hypotheses EstimateUpdate::hypotheses(double rival_weight_ratio) const {
  Hypotheses h = hypothesesOf(estimate_, rival_weight_ratio);
  addLookAlikes(look_alike_places_, &h);
  return h;
}

}  // namespace pf

// Monte Carlo localization: the particle filter that composes the motion
// model, a sensor model (sensor_model.h: the likelihood field, with or
// without beam skipping, or the beam model), the resampler and the pose
// estimator.
//
// Thrun, Burgard & Fox, "Probabilistic Robotics" (2005), table 8.2 (MCL) with
// the augmentation of table 8.3 (random particles injected when the short-term
// average of the measurement likelihood falls below the long-term one), and
// KLD-sampling (Fox 2003) to adapt the particle count.
//
// One update is a pipeline of named parts: UpdateGate (whether and why),
// MotionUpdate (the odometry, with OdometryFaultTracker's share of faults),
// SensorUpdate (the weights, tempered by temperingEssFraction, with
// GlobalSearch's smoothed likelihood while a global cloud is sparse), the estimate
// and ConfidenceTracker (the verdict, with LookAlikes: the map's look-alike
// places the scan fits as well), EstimateRefinement (the scan fit, and
// map -> odom), and Recovery (the resampling, with its strategies). The
// design decisions behind them, with their evidence: docs/design.md.
//
// Deterministic: the same parameters (seed included) and the same calls give
// the same particles, bit for bit.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/estimate/confidence_tracker.h"
#include "pf_localization/core/estimate/confidence_verdict.h"
#include "pf_localization/core/estimate/estimate_refinement.h"
#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/estimate/scan_matcher.h"
#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/filter/resampler.h"
#include "pf_localization/core/filter/update_gate.h"
#include "pf_localization/core/map/map_change_layer.h"
#include "pf_localization/core/map/map_change_mask.h"
#include "pf_localization/core/map/map_evidence.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/motion/motion_update.h"
#include "pf_localization/core/recovery/global_search.h"
#include "pf_localization/core/recovery/look_alike_places.h"
#include "pf_localization/core/recovery/recovery.h"
#include "pf_localization/core/sensor/beam_model.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/sensor/sensor_update.h"
#include "pf_localization/core/sensor/transient_beams.h"
#include "pf_localization/core/util/random.h"

namespace pf {

/// The sensor model `params` names, on `grid`. Throws std::invalid_argument
/// for an out-of-range parameter.
std::unique_ptr<SensorModel> makeSensorModel(const OccupancyGrid& grid,
                                             const ParticleFilterParams& params);

/// What one call to ParticleFilter::update did.
struct UpdateReport {
  bool updated = false;                        // motion and sensor update ran
  SkipReason skip_reason = SkipReason::kNone;  // why not, when !updated
  std::string skip_detail;                     // the specifics, for the log (may be empty)
  int beams_used = 0;
  int beams_dropped = 0;  // without a reading (the masked ones not counted)
  int beams_masked = 0;  // seeing something that moved in while the robot stood (transient_beams.h)
  int beams_changed =
      0;  // seeing a change of the map where the tracked pose fits the rest (map_change_mask.h)
  // What the beams said of the map at the tracked pose (map_change_mask.h):
  // all zero when they were not judged (no tracked pose).
  EvidenceCounts map_evidence;
  // Whether the scan agreed with the map there (the beams seeing changes
  // were masked), and the share of its beams that saw a change then.
  bool map_agrees = false;
  double map_changed_share = 0.0;
  int beams_skipped = 0;  // of beams_used, left out by beam skipping
  std::size_t particles = 0;
  double ess = 0.0;  // before resampling
  bool resampled = false;
  double mean_beam_likelihood = 0.0;  // geometric mean over beams, weighted over particles
  std::size_t injected = 0;           // random particles added by recovery
  double tempering = 1.0;             // exponent applied to this scan's likelihood (1: none)
  double search_sigma = 0.0;  // the hit std dev of GlobalSearch's smoothed model (0: the model's)
  bool expanded = false;      // the survivors were spread by expansion resetting
  // Look-alike places (look_alike_places.h) the scan fits as well as the estimate,
  // and those it fits clearly better, where recovery added `moved` particles.
  std::size_t look_alikes = 0;
  std::size_t look_alikes_better = 0;
  std::size_t moved = 0;
  double fault_fraction = 0.0;  // share of particles to assume an odometry fault next step
  // The update came before update_min_d / update_min_a because the scan no
  // longer fitted at the pose the odometry predicted (update_fit_drop).
  bool fit_dropped = false;
  // The scan fit of the estimate (when refine_estimate is on): accepted, or
  // the reason it was not, as in refinement.rejection.
  ScanRefinement refinement;
};

/// What a skipped update says in a log line: the reason and its detail.
std::string skipMessage(const UpdateReport& report);

class ParticleFilter {
 public:
  /// Throws std::invalid_argument (see validate()).
  explicit ParticleFilter(const ParticleFilterParams& params);

  const ParticleFilterParams& params() const { return params_; }

  /// Replaces the parameters while running (dynamic_reconfigure): the
  /// particles, the estimate and the recovery averages are kept; the motion
  /// model and, when a sensor parameter changed, the likelihood field are
  /// built anew from `params`, and a larger max_particles reserves (and
  /// prefaults) the storage as the constructor does. The seed is not
  /// changed: the random stream goes on. Throws std::invalid_argument (see
  /// validate()) and then leaves everything as it was.
  void setParams(const ParticleFilterParams& params);

  /// Installs a map (rebuilding the likelihood field). If particles exist and
  /// the current estimate lies in free space of the new map they are kept;
  /// otherwise the filter becomes uninitialised. Returns whether they were kept.
  /// Throws std::invalid_argument for an empty map.
  bool setMap(const OccupancyGrid& grid);
  bool hasMap() const { return sensor_.hasModel(); }
  /// The sensor model on the map; null without a map.
  const SensorModel* sensorModel() const { return sensor_.get(); }
  const OccupancyGrid* map() const {
    return sensor_.hasModel() ? &sensor_.model().field().grid() : nullptr;
  }
  /// Where the world no longer matches the map, learned from the scans of
  /// the updates that agreed with it at the tracked pose and left the filter
  /// not lost, placed at the estimate (map_change_layer.h); null without a
  /// map, and a new map starts it anew. The scans are judged on the map as
  /// the layer has it (map_evidence.h): its obstacles seen gone no longer
  /// stop rays, and a beam that ends on one it has seen added sees a change.
  const MapChangeLayer* mapChanges() const { return layer_ ? &*layer_ : nullptr; }

  /// Particles drawn around `mean` from a Gaussian with covariance `cov`
  /// (x, y, yaw). Throws std::invalid_argument for a non-finite pose or a
  /// covariance that is not symmetric positive semi-definite.
  void initializeGaussian(const Pose2& mean, const Eigen::Matrix3d& cov);
  /// Particles spread uniformly over the map's free cells (global localization).
  /// Throws std::logic_error without a map or when the map has no free cell.
  void initializeUniform();
  bool isInitialized() const { return !particles_.empty(); }

  /// Feeds the odometry pose at the scan's time and the scan, or the scans
  /// of several sensors placed on the robot at that time (scan_group.h).
  /// Runs a filter
  /// update when the robot moved enough, when the scan stopped fitting the
  /// pose the odometry predicts (update_fit_drop), on the first scan after
  /// an initialisation, or after requestNoMotionUpdate().
  UpdateReport update(const Pose2& odom, const ScanGroup& scans);

  /// The next update() runs even without motion.
  void requestNoMotionUpdate() { gate_.requestUpdate(); }

  const ParticleSet& particles() const { return particles_; }
  /// The estimate: its pose and covariance are the refined ones when the
  /// last update's scan fit was accepted; clusters[0].mean stays the cloud's.
  const PoseEstimate& estimate() const { return estimate_; }
  /// How far to trust the estimate, as of the last update.
  const Confidence& confidence() const { return confidence_.confidence(); }
  /// The places the estimate's clusters hold with real weight: the
  /// heaviest, every rival confidence() counts, and any cluster with
  /// kMinHypothesisShare of the weight (hypotheses.h); then the look-alike
  /// places the last scan fitted as well that the cloud does not hold.
  Hypotheses hypotheses() const;

  /// map -> odom: the estimate composed with the inverse of the odometry pose
  /// it was computed at, or the latest accepted scan fit since that update
  /// (EstimateRefinement). Empty until the first update after an
  /// initialisation.
  std::optional<Pose2> mapToOdom() const;

 private:
  // Where the last estimate would be now had the odometry been right (or the
  // pose a cloud was just drawn around); none after a global initialisation
  // until its first update.
  std::optional<Pose2> trackedPose(const Pose2& odom) const;
  // The scans with the beams that see something that moved in while the
  // robot stood masked (transient_beams.h), judged from the last estimate.
  ScanGroup maskTransients(const Pose2& odom, const ScanGroup& measured);
  // The tracked pose at `odom` when it is known well enough to judge beams
  // from (judgesFromTrackedPose).
  std::optional<Pose2> judgingPose(const Pose2& odom) const;
  // The scans with the beams that see a change of the map from `robot`
  // masked, while that pose explains the rest (map_change_mask.h); none:
  // nothing judged.
  ScanGroup maskMapChanges(const std::optional<Pose2>& robot, const ScanGroup& scans);
  // Whether the tracked pose at `odom` is known well enough to judge beams
  // from: one place, told apart, not lost, a short step of odometry since.
  bool judgesFromTrackedPose(const Pose2& odom) const;
  // Weighs the cloud by `scans`, an update that brings a share `view` of a
  // new view (view_share.h), and takes its fit into recovery's averages.
  void weigh(const std::vector<PreparedScan>& scans, double view, UpdateReport* report);
  // The estimate of the weighted cloud and the verdict on it; `predicted`:
  // the last estimate moved by the odometry since (none on a first update).
  // `scans` are the beams weighed; `all_beams` every beam, those masked for
  // changes of the map too: the gate's fit and the look-alikes take them (what
  // the map lacks at the tracked place may be what the place the robot was
  // carried to has).
  void estimateAndJudge(const std::vector<PreparedScan>& scans,
                        const std::vector<PreparedScan>& all_beams,
                        const std::optional<Pose2>& predicted, UpdateReport* report);
  // The places pf_hypotheses lists after the cloud's: the look-alikes of
  // the estimate (`view`) and, when the cloud holds several `places`, of
  // each listed one, that the scans fit as well as the estimate.
  void listLookAlikes(const std::vector<PreparedScan>& scans, const LookAlikeView& view,
                      std::size_t places);
  void resample(UpdateReport* report);
  void restartAfterInitialization(bool place_given);
  // Adds `scans` to the layer of the map's changes after an update whose
  // scans agreed with the map, and shares what it learned with the judging.
  void learnMapChanges(const ScanGroup& scans, bool map_agrees);
  // Tells the judging (evidence_) the layer's added and removed cells: those
  // that changed, or (`all`) every one, for a new MapEvidence.
  void shareMapChanges(bool all);
  void reserveStorage(std::size_t max_particles);

  ParticleFilterParams params_;
  int threads_;  // params_.threads resolved (resolvedThreads)
  Random random_;
  SensorUpdate sensor_;  // the sensor model (none without a map) and its scratch
  GlobalSearch search_;  // the smoothed model while a global initialisation's cloud is sparse
  MotionUpdate motion_;  // the motion model and the odometry fault share
  ParticleSet particles_;
  PoseEstimate estimate_;
  TransientBeams transients_;            // what the beams saw while the robot stood still
  std::vector<LaserScan> masked_scans_;  // the scans with the transient beams masked
  std::optional<MapEvidence> evidence_;  // the map's rays (none without a map)
  MapChangeMask changes_;
  std::optional<MapChangeLayer> layer_;   // over the map (none without one)
  std::vector<LaserScan> changed_scans_;  // the scans with the beams seeing changes masked
  UpdateGate gate_;                       // holds the odometry of the last update
  ConfidenceTracker confidence_;
  LookAlikes look_alikes_;  // the map's symmetries, and what each scan says of them
  // The last scan's look-alikes of the places the cloud holds, fitting as
  // well as the estimate.
  std::vector<LookAlikePlace> look_alike_places_;
  std::size_t places_ = 0;  // the places the last update's cloud holds (hypothesesOf)
  EstimateRefinement refinement_;
  Recovery recovery_;
};

}  // namespace pf

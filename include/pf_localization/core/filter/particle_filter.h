// Monte Carlo localization: the particle filter, one update a pipeline of
// stages, each an object that owns its state and reports its own part:
//
//   screen   BeamScreen: each beam screened once, against what moved in while
//            the robot stood and against the map's changes
//   gate     UpdateGate: whether the scan updates, and why not
//   motion   MotionUpdate: the odometry, with OdometryFaultTracker's share of faults
//   weigh    SensorUpdate: the likelihood of the fitting beams, tempered, with
//            GlobalSearch's smoothed model while a global cloud is sparse
//   judge    EstimateUpdate: the clusters' estimate and the verdict on it,
//            with the map's look-alike places
//   refine   EstimateUpdate: the scan fit of the estimate, and map -> odom
//   recover  Recovery: the resampling, with its strategies
//   learn    BeamScreen: the map's changes, from the scans that agreed with it
//
// The screening runs first because the gate decides on the beams it kept.
// Thrun, Burgard & Fox, "Probabilistic Robotics" (2005), table 8.2 (MCL) with
// the augmentation of table 8.3 (random particles injected when the short-term
// average of the measurement likelihood falls below the long-term one), and
// KLD-sampling (Fox 2003) to adapt the particle count. docs/how-it-works has a
// page per stage; the design decisions behind them, with their evidence, are
// in docs/design.md.
//
// Deterministic: the same parameters (seed included) and the same calls give
// the same particles, bit for bit.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/estimate/estimate_update.h"
#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/estimate/scan_refiner.h"
#include "pf_localization/core/filter/beam_screen.h"
#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/filter/prepared_map.h"
#include "pf_localization/core/filter/update_gate.h"
#include "pf_localization/core/map/map_change_layer.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/motion/motion_update.h"
#include "pf_localization/core/recovery/recovery.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/sensor/sensor_update.h"
#include "pf_localization/core/util/random.h"

namespace pf {

/// The sensor model `params` names, on `grid` (moved into its field).
/// Throws std::invalid_argument for an out-of-range parameter.
std::unique_ptr<SensorModel> makeSensorModel(OccupancyGrid grid,
                                             const ParticleFilterParams& params);

/// What one call to ParticleFilter::update did: each stage's part (the
/// gate's says why an update did not run), and the cloud after it.
struct UpdateReport : GateReport, ScreenReport, Weighing, JudgeReport, ResampleOutcome {
  bool updated = false;  // motion and sensor update ran
  std::size_t particles = 0;
  double ess = 0.0;             // before resampling
  double fault_fraction = 0.0;  // share of particles to assume an odometry fault next step
  // The scan fit of the estimate (when refine_estimate is on): accepted, or
  // the reason it was not, as in refinement.rejection.
  ScanRefinement refinement;

  // Each stage's part, as that stage returns it.
  GateReport& gate() { return *this; }
  ScreenReport& screen() { return *this; }
  Weighing& weighing() { return *this; }
  JudgeReport& judge() { return *this; }
  ResampleOutcome& recovery() { return *this; }
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

  /// Installs a map. If particles exist and the current estimate lies in
  /// free space of the new map they are kept; otherwise the filter becomes
  /// uninitialised. Returns whether they were kept. Throws
  /// std::invalid_argument for an empty map. The filter keeps `grid` (moved
  /// in: a large map is not held twice).
  bool setMap(OccupancyGrid grid) {
    return setMap(PreparedMap::build(std::move(grid), mapRecipe()));
  }
  /// The same with the map's structures built beforehand, from mapRecipe()
  /// (prepared_map.h): only a swap, unless a sensor parameter changed since
  /// the recipe was taken, which builds them again.
  bool setMap(PreparedMap map);
  /// Takes the map out, with what its change layer learned and its
  /// look-alike places, for a later setMap to install again as it was (a
  /// building's floors keep theirs: ros/localizer/floors.h); none without a
  /// map. The particles stay; the filter has no map until the next setMap.
  std::optional<PreparedMap> releaseMap();
  /// What building a map for this filter needs, to build it elsewhere.
  PreparedMap::Recipe mapRecipe() const { return {params_, sensor_.ranges()}; }
  bool hasMap() const { return sensor_.hasModel(); }
  /// Scans from a sensor whose range_max is `range_max` (as it reports it)
  /// are to come: what weighing them needs (the likelihood table) is built
  /// with the map, now or when one is set, not by the update that first
  /// weighs one. Non-finite or non-positive values are ignored.
  void expectScanRange(double range_max);
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
  const MapChangeLayer* mapChanges() const { return screen_.layer(); }
  /// That layer restored from `state` (MapChangeLayer::encode(), learned on
  /// this map), the scans judged on it from now on: empty, or why it was
  /// refused (the layer is then empty). Without a map: refused.
  std::string restoreMapChanges(const std::string& state) { return screen_.restoreLayer(state); }
  /// That layer emptied: the scans are judged on the map as it is.
  void clearMapChanges() { screen_.clearLayer(); }

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
  const PoseEstimate& estimate() const { return estimate_.estimate(); }
  /// How far to trust the estimate, as of the last update.
  const Confidence& confidence() const { return estimate_.confidence(); }
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
  // Where the last estimate would be at `odom` had the odometry been right
  // (or the pose a cloud was just drawn around), and whether it is known
  // well enough to judge beams from.
  TrackedPose tracked(const Pose2& odom) const;
  // The motion stage: moves the particles from the last update's odometry
  // to `odom` (none on a first update); returns the last estimate moved
  // the same way, had the odometry been right.
  std::optional<Pose2> moveCloud(const GateDecision& gate, const Pose2& odom);
  // The stages after the estimate's: recovery's averages and plan take the
  // update's fit, its share of a new view `view` and the look-alikes the
  // scan fits clearly better (`better`), then the cloud is resampled.
  ResampleOutcome resampleAndRecover(const UpdateReport& report, double view,
                                     std::vector<Pose2> better);
  void restartAfterInitialization(const PoseEstimate& estimate, bool place_given);
  void reserveStorage(std::size_t max_particles);

  ParticleFilterParams params_;
  int threads_;  // params_.threads resolved (resolvedThreads)
  Random random_;
  ParticleSet particles_;
  // The stages, in the order update() runs them; the map is the sensor
  // model's (none without one).
  BeamScreen screen_;
  UpdateGate gate_;  // holds the odometry of the last update
  MotionUpdate motion_;
  SensorUpdate sensor_;
  EstimateUpdate estimate_;
  Recovery recovery_;
};

}  // namespace pf

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
// The filter runs an update only after the robot has moved update_min_d or
// turned update_min_a since the last one, and on the first scan after an
// initialisation: a robot standing still would otherwise keep multiplying
// the same evidence into its weights and grow falsely confident. It updates
// sooner when a scan no longer fits where the odometry says the robot is
// (update_fit_drop): that is when waiting for more odometry costs most.
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

#include "pf_localization/core/beam_model.h"
#include "pf_localization/core/confidence.h"
#include "pf_localization/core/laser_scan.h"
#include "pf_localization/core/likelihood_field_model.h"
#include "pf_localization/core/occupancy_grid.h"
#include "pf_localization/core/odometry_motion_model.h"
#include "pf_localization/core/particle_filter_params.h"
#include "pf_localization/core/particle_set.h"
#include "pf_localization/core/pose_estimator.h"
#include "pf_localization/core/random.h"
#include "pf_localization/core/resampler.h"
#include "pf_localization/core/scan_refiner.h"
#include "pf_localization/core/sensor_model.h"
#include "pf_localization/core/weighting.h"

namespace pf {

/// The sensor model `params` names, on `grid`. Throws std::invalid_argument
/// for an out-of-range parameter.
std::unique_ptr<SensorModel> makeSensorModel(const OccupancyGrid& grid,
                                             const ParticleFilterParams& params);

/// What one call to ParticleFilter::update did.
struct UpdateReport {
  bool updated = false;     // motion and sensor update ran
  std::string skip_reason;  // why not, when !updated
  int beams_used = 0;
  int beams_dropped = 0;
  int beams_skipped = 0;  // of beams_used, left out by beam skipping
  std::size_t particles = 0;
  double ess = 0.0;  // before resampling
  bool resampled = false;
  double mean_beam_likelihood = 0.0;  // geometric mean over beams, weighted over particles
  std::size_t injected = 0;           // random particles added by recovery
  double tempering = 1.0;             // exponent applied to this scan's likelihood (1: none)
  bool expanded = false;              // the survivors were spread by expansion resetting
  double fault_fraction = 0.0;        // share of particles to assume an odometry fault next step
  // The update came before update_min_d / update_min_a because the scan no
  // longer fitted at the pose the odometry predicted (update_fit_drop).
  bool fit_dropped = false;
  // The scan fit of the estimate (when refine_estimate is on): accepted, or
  // the reason it was not, as in refinement.rejection.
  ScanRefinement refinement;
};

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
  bool hasMap() const { return static_cast<bool>(model_); }
  const OccupancyGrid* map() const { return model_ ? &model_->field().grid() : nullptr; }

  /// Particles drawn around `mean` from a Gaussian with covariance `cov`
  /// (x, y, yaw). Throws std::invalid_argument for a non-finite pose or a
  /// covariance that is not symmetric positive semi-definite.
  void initializeGaussian(const Pose2& mean, const Eigen::Matrix3d& cov);
  /// Particles spread uniformly over the map's free cells (global localization).
  /// Throws std::logic_error without a map or when the map has no free cell.
  void initializeUniform();
  bool isInitialized() const { return !particles_.empty(); }

  /// Feeds the odometry pose at the scan's time and the scan. Runs a filter
  /// update when the robot moved enough, when the scan stopped fitting the
  /// pose the odometry predicts (update_fit_drop), on the first scan after
  /// an initialisation, or after requestNoMotionUpdate().
  UpdateReport update(const Pose2& odom, const LaserScan& scan);

  /// The next update() runs even without motion.
  void requestNoMotionUpdate() { force_update_ = true; }

  const ParticleSet& particles() const { return particles_; }
  /// The estimate: its pose and covariance are the refined ones when the
  /// last update's scan fit was accepted; clusters[0].mean stays the cloud's.
  const PoseEstimate& estimate() const { return estimate_; }
  /// How far to trust the estimate, as of the last update.
  const Confidence& confidence() const { return confidence_; }

  /// map -> odom: the estimate composed with the inverse of the odometry pose
  /// it was computed at. Empty until the first update after an initialisation.
  std::optional<Pose2> mapToOdom() const;

 private:
  void weigh(const PreparedScan& scan, UpdateReport* report);
  void resample(UpdateReport* report);
  void adaptFaultFraction();
  // The scan, prepared, when it fits the pose the odometry predicts
  // `since_update` after the last update's estimate clearly worse than that
  // update's scan fitted its estimate (update_fit_drop); nothing otherwise.
  std::optional<PreparedScan> fitDropped(const LaserScan& scan, const Pose2& since_update) const;
  void refineEstimate(const LaserScan& scan, UpdateReport* report);
  void refineBetweenUpdates(const Pose2& odom, const LaserScan& scan, UpdateReport* report);
  bool refinedIsCurrent() const;
  Pose2 randomFreePose();
  void restartAfterInitialization();
  void reserveStorage(std::size_t max_particles);

  ParticleFilterParams params_;
  Random random_;
  OdometryMotionModel motion_model_;
  std::unique_ptr<SensorModel> model_;
  ParticleSet particles_;
  ParticleSet spare_;  // the resampler's output, swapped with particles_
  PoseEstimate estimate_;
  Confidence confidence_;
  std::optional<Pose2> odom_at_update_;
  // map -> odom of the latest accepted scan fit, which may be newer than the
  // last update, and odom_at_update_ at that update. An update clears it
  // before fitting; a rejected fit between updates leaves the last one.
  struct RefinedMapToOdom {
    Pose2 map_to_odom;
    Pose2 odom_at_update;
    Pose2 odom_at_fit;  // the odometry at the scan that was fitted
  };
  std::optional<RefinedMapToOdom> refined_;
  bool force_update_ = false;
  // The share of the last update's beams that ended within
  // update_fit_distance of an obstacle at its estimate (see update_fit_drop).
  double fit_at_update_ = 0.0;
  bool restart_ = false;  // the next update follows an initialisation
  bool has_estimate_ = false;
  double w_slow_ = 0.0;
  double w_fast_ = 0.0;
  int low_fit_updates_ = 0;  // consecutive updates with w_fast below the trigger
  LocalizationState fit_state_ = LocalizationState::kLost;  // the verdict before holdAfterJump
  double fault_fraction_ = 0.0;  // of the next motion update (adaptFaultFraction)
  std::vector<uint8_t> faulty_;  // which particles took an odometry fault in this update
  int settle_left_ = 0;          // updates until a jumped estimate may be localized (holdAfterJump)
  bool expand_ = false;          // this scan's fit collapsed: spread the survivors
  WeightingScratch weighting_;
  std::vector<double> log_likelihood_;
};

}  // namespace pf

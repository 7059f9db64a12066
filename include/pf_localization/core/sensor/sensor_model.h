// The sensor model as the particle filter sees it: one small interface, so
// that ParticleFilter composes whichever model the configuration names
// (likelihood field, the same with beam skipping, beam model) without a
// branch of its own, as Beluga composes its models through one concept
// (Ekumen, "Beluga", github.com/Ekumen-OS/beluga).
//
// A model turns a scan into its usable beams once (prepare), then scores
// every particle against the map in log space (logLikelihoods). Every model
// keeps the map's likelihood field too: the filter draws free cells from its
// grid, judges its confidence by how many end points lie near an obstacle
// (hitFraction), and the scan refiner fits to its distances.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/sensor/laser_scan.h"

namespace pf {

/// The usable beams of one scan in the robot's base frame, computed once per scan.
struct PreparedScan {
  std::vector<float> x;      // m, end point
  std::vector<float> y;      // m
  std::vector<float> range;  // m, measured range (what the beam model compares)
  std::vector<float> angle;  // rad, direction of the beam in the robot frame
  double sensor_x = 0.0;     // m, where the beams start, in the robot frame
  double sensor_y = 0.0;     // m
  double range_max = 0.0;    // the range_max that scales z_rand
  double weight = 1.0;       // LaserScan::weight: the log-likelihood's factor
  int dropped = 0;           // invalid beams dropped before subsampling
  std::size_t size() const { return x.size(); }
};

/// The usable beams of `scan`, evenly subsampled to at most `max_beams`
/// (<= 0: all), within [range_min, range_max] when those are tighter than the
/// scan's (0: the scan's). End points too far to be placed in float cells of
/// size `resolution` are dropped like invalid beams.
PreparedScan prepareScan(const LaserScan& scan, int max_beams, double range_min, double range_max,
                         double resolution);

/// The range_max a scan is scored with: the scan's own, or `range_max` where
/// that is positive and tighter (laser_max_range).
inline double scoredRangeMax(double scan_range_max, double range_max) {
  return range_max > 0.0 ? std::min(range_max, scan_range_max) : scan_range_max;
}

class SensorModel {
 public:
  virtual ~SensorModel() = default;

  /// The map's likelihood field (distances to the nearest obstacle), and through it the grid.
  virtual const DistanceField& field() const = 0;

  /// The usable beams with the model's own beam budget, and with another (<= 0: all).
  virtual PreparedScan prepare(const LaserScan& scan) const = 0;
  virtual PreparedScan prepare(const LaserScan& scan, int max_beams) const = 0;

  /// likelihood_exponent * log p(scan | pose) for one pose, every beam counted.
  virtual double logLikelihood(const PreparedScan& scan, const Pose2& pose) const = 0;

  /// likelihood_exponent * log p(scan | particle) for every particle, into
  /// `log_likelihood`. Returns how many of the scan's beams were counted: a
  /// model may leave out beams the cloud as a whole does not explain (beam skipping).
  virtual std::size_t logLikelihoods(const PreparedScan& scan, const ParticleSet& particles,
                                     std::vector<double>* log_likelihood) const = 0;

  /// The fraction of the scan's beams whose end point, placed from `pose`,
  /// lies within `distance` metres of an obstacle (0 for an empty scan).
  virtual double hitFraction(const PreparedScan& scan, const Pose2& pose, double distance) const;

  /// Builds now what scoring scans of `range_max` needs (the likelihood
  /// field's table), so that the update that first scores one does not.
  virtual void warmUp(double /*range_max*/) const {}

  /// The same model with its hit component widened to the std dev
  /// `sigma_hit` (m), for a sparse cloud (global_search.h); null when the
  /// model has no such component to widen.
  virtual std::unique_ptr<SensorModel> smoothed(double /*sigma_hit*/) const { return nullptr; }
};

}  // namespace pf

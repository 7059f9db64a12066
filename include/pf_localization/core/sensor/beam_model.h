// The beam model of range finders: weighs each particle by how well every
// measured range matches the range at which that beam, cast from the
// particle's pose, would hit the map.
//
// Thrun, Burgard & Fox, "Probabilistic Robotics" (2005), table 6.1. For a
// beam measuring z where the map says z* (ray casting, capped at range_max):
//   p = z_hit   * N(z; z*, sigma_hit)
//     + z_short * lambda_short exp(-lambda_short z)   if z < z*
//     + z_max   * 1                                   if z >= range_max
//     + z_rand  / range_max                           if z <  range_max
// As in amcl, the normalisers eta of the truncated hit and short densities
// (eq. 6.4, 6.7) are left out; the beams are independent, so a particle's
// log-likelihood is the sum of the beams' log p, raised to
// likelihood_exponent as in the likelihood field model. prepare() drops
// readings at or beyond range_max like any invalid beam (a Neato reports
// "nothing within range" and a dropout alike), so the z_max term only
// matters for scans whose range_max is above the model's laser_max_range.
//
// Ray casting is the cost: one cast per particle and beam, sped up by the
// distance transform (distance_field_ray_caster.h). The model also keeps the
// likelihood field, which the filter and the scan refiner use.
#pragma once

#include <vector>

#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/map/distance_field_ray_caster.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/sensor/sensor_model.h"

namespace pf {

/// The beam model's own terms. z_hit, z_rand, sigma_hit, the beam budget,
/// the range limits, likelihood_exponent, max_distance (of the likelihood
/// field kept for the filter) and threads are shared with the likelihood
/// field model and come from LikelihoodFieldModelParams.
struct BeamModelParams {
  double z_short = 0.1;       // weight of the unexpected-obstacle component (unitless, >= 0)
  double z_max = 0.05;        // weight of the max-range component (unitless, >= 0)
  double lambda_short = 0.1;  // 1/m, rate of the exponential short component (> 0)
};

/// The beam model's own parameters (parameter_table.h); it shares the
/// likelihood field's too.
const ParameterTable<BeamModelParams>& beamModelParameters();

class BeamModel : public SensorModel {
 public:
  /// Throws std::invalid_argument naming the parameter when one is out of range.
  BeamModel(const OccupancyGrid& grid, const LikelihoodFieldModelParams& shared,
            const BeamModelParams& params);

  const DistanceField& field() const override { return field_; }
  const DistanceFieldRayCaster& rayCaster() const { return caster_; }

  PreparedScan prepare(const LaserScan& scan) const override {
    return prepare(scan, shared_.max_beams);
  }
  PreparedScan prepare(const LaserScan& scan, int max_beams) const override;

  double logLikelihood(const PreparedScan& scan, const Pose2& pose) const override;
  std::size_t logLikelihoods(const PreparedScan& scan, const ParticleSet& particles,
                             std::vector<double>* log_likelihood) const override;

  /// p of one beam measuring `range` where the map says `expected`, before tempering.
  double beamProbability(double range, double expected, double range_max) const;

 private:
  // beam_cos, beam_sin: the beams' directions in the robot frame.
  double scorePose(const PreparedScan& scan, const double* beam_cos, const double* beam_sin,
                   double x, double y, double yaw) const;

  LikelihoodFieldModelParams shared_;
  BeamModelParams params_;
  DistanceField field_;
  DistanceFieldRayCaster caster_;
};

}  // namespace pf

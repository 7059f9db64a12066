#include "pf_localization/core/sensor/beam_model.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pf_localization/core/filter/particle_blocks.h"

namespace pf {

const ParameterTable<BeamModelParams>& beamModelParameters() {
  using P = BeamModelParams;
  using I = ParamInfo;
  static const ParameterTable<P> table = {
      member(&P::z_short, I("laser_z_short", "", "beam model: weight of unexpected obstacles")
                              .in(Range::atLeast(0))
                              .amcl()
                              .live(0, 1)),
      member(&P::z_max, I("laser_z_max", "", "beam model: weight of max-range readings")
                            .in(Range::atLeast(0))
                            .amcl()
                            .live(0, 1)),
      member(&P::lambda_short,
             I("laser_lambda_short", "1/m", "beam model: rate of the short readings")
                 .in(Range::above(0))
                 .amcl()
                 .live(0.001, 10)),
  };
  return table;
}

BeamModel::BeamModel(const OccupancyGrid& grid, const LikelihoodFieldModelParams& shared,
                     const BeamModelParams& params)
    : shared_(shared),
      params_(params),
      field_(grid, shared.max_distance, shared.threads),
      caster_(grid) {
  checkRanges(beamModelParameters(), params);
  validate(shared);
}

PreparedScan BeamModel::prepare(const LaserScan& scan, int max_beams) const {
  return prepareScan(scan, max_beams, shared_.range_min, shared_.range_max,
                     field_.grid().resolution());
}

double BeamModel::beamProbability(double range, double expected, double range_max) const {
  const double s = shared_.sigma_hit;
  const double e = range - expected;
  double p = shared_.z_hit * std::exp(-0.5 * e * e / (s * s)) / (s * std::sqrt(2.0 * M_PI));
  if (range < expected) {
    p += params_.z_short * params_.lambda_short * std::exp(-params_.lambda_short * range);
  }
  if (range >= range_max) {
    p += params_.z_max;
  } else {
    p += shared_.z_rand / range_max;
  }
  return p;
}

double BeamModel::scorePose(const PreparedScan& scan, const double* beam_cos,
                            const double* beam_sin, double x, double y, double yaw) const {
  const DistanceFieldRayCaster& rc = caster_;
  const double res = rc.resolution();
  const Pose2& o = rc.origin();
  const double c = std::cos(yaw), s = std::sin(yaw);
  // The sensor in the world, then in the grid's frame in cells: the origin's
  // rotation is applied once per particle, not per beam.
  const double wx = x + c * scan.sensor_x - s * scan.sensor_y - o.x;
  const double wy = y + s * scan.sensor_x + c * scan.sensor_y - o.y;
  const double oc = std::cos(o.yaw), os = std::sin(o.yaw);
  const double cx = (oc * wx + os * wy) / res, cy = (-os * wx + oc * wy) / res;
  // The beams' directions in the grid are the robot-frame ones turned by
  // this rotation: two multiplications per beam instead of a cos and a sin.
  const double rc0 = std::cos(yaw - o.yaw), rs0 = std::sin(yaw - o.yaw);
  double sum = 0.0;
  for (std::size_t b = 0; b < scan.size(); ++b) {
    const double dx = rc0 * beam_cos[b] - rs0 * beam_sin[b];
    const double dy = rs0 * beam_cos[b] + rc0 * beam_sin[b];
    const double expected = rc.castInCells(cx, cy, dx, dy, scan.range_max);
    sum += std::log(beamProbability(scan.range[b], expected, scan.range_max));
  }
  return shared_.likelihood_exponent * sum;
}

namespace {

void beamDirections(const PreparedScan& scan, std::vector<double>* cos_out,
                    std::vector<double>* sin_out) {
  cos_out->resize(scan.size());
  sin_out->resize(scan.size());
  for (std::size_t b = 0; b < scan.size(); ++b) {
    (*cos_out)[b] = std::cos(static_cast<double>(scan.angle[b]));
    (*sin_out)[b] = std::sin(static_cast<double>(scan.angle[b]));
  }
}

}  // namespace

double BeamModel::logLikelihood(const PreparedScan& scan, const Pose2& pose) const {
  std::vector<double> bc, bs;
  beamDirections(scan, &bc, &bs);
  return scorePose(scan, bc.data(), bs.data(), pose.x, pose.y, pose.yaw);
}

std::size_t BeamModel::logLikelihoods(const PreparedScan& scan, const ParticleSet& particles,
                                      std::vector<double>* log_likelihood) const {
  log_likelihood->resize(particles.size());
  std::vector<double> bc, bs;
  beamDirections(scan, &bc, &bs);
  // Every particle is scored alone: the result does not depend on the threads.
  forEachSlice(particles.size(), shared_.threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      (*log_likelihood)[i] =
          scorePose(scan, bc.data(), bs.data(), particles.x[i], particles.y[i], particles.yaw[i]);
    }
  });
  return scan.size();
}

}  // namespace pf

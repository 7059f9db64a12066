// A smooth distance field: the likelihood field's per-cell distances to the
// obstacles' surfaces (DistanceField::surfaceDistance: inside a thick
// obstacle they grow again), interpolated bicubically between cell centres,
// with the gradient.
//
// Keys, "Cubic convolution interpolation for digital image processing", IEEE
// Trans. ASSP 29(6), 1981, with a = -0.5: the Catmull-Rom spline through the
// cell centres. It passes through every sample, is continuously
// differentiable, and reproduces linear ramps exactly (the field beside a
// straight wall). Cartographer's Ceres scan matcher (Hess et al., "Real-Time
// Loop Closure in 2D LIDAR SLAM", ICRA 2016) interpolates its grid the same
// way, so that Gauss-Newton sees a gradient that changes continuously instead
// of the steps of a per-cell lookup, which has no useful gradient at all.
//
// Within a cell and a half of the map's edge, the edge cells are repeated
// outwards; further out the distance is max_distance, as in the likelihood
// field.
#pragma once

#include <cstddef>

#include "pf_localization/core/map/distance_field.h"

namespace pf {

/// The interpolated distance at a point and its gradient, in the world frame.
struct FieldSample {
  double distance = 0.0;  // m
  double dx = 0.0;        // d distance / d x (unitless)
  double dy = 0.0;        // d distance / d y
};

class BicubicDistanceField {
 public:
  /// Keeps a reference: `field` must outlive this object.
  explicit BicubicDistanceField(const DistanceField& field);

  /// The distance at world point (wx, wy) and its gradient. More than a
  /// cell and a half off the map, or at a non-finite point: max_distance
  /// with a zero gradient.
  FieldSample sample(double wx, double wy) const;
  /// sample(wx[i], wy[i]) into out[i] for each i < n, the same bits: where
  /// the processor has AVX2, four points at a time.
  void sample(const double* wx, const double* wy, std::size_t n, FieldSample* out) const;

  /// m: the map's cell size.
  double resolution() const { return 1.0 / inv_resolution_; }

 private:
  const DistanceField& field_;
  // The grid's geometry, taken once: sample() runs for every beam of every
  // Gauss-Newton evaluation.
  double cos_yaw_, sin_yaw_, inv_resolution_, origin_x_, origin_y_;
  int width_, height_;
  // Whether every cell's index fits the 32-bit lanes of the four-point path.
  bool int_indices_;
};

}  // namespace pf

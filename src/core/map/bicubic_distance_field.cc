#include "pf_localization/core/map/bicubic_distance_field.h"

#include <cmath>

namespace pf {
namespace {

// Catmull-Rom weights of the four samples around t in [0, 1) (at -1, 0, 1,
// 2), and their derivatives with respect to t.
void cubicWeights(double t, double w[4], double dw[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = -0.5 * t3 + t2 - 0.5 * t;
  w[1] = 1.5 * t3 - 2.5 * t2 + 1.0;
  w[2] = -1.5 * t3 + 2.0 * t2 + 0.5 * t;
  w[3] = 0.5 * t3 - 0.5 * t2;
  dw[0] = -1.5 * t2 + 2.0 * t - 0.5;
  dw[1] = 4.5 * t2 - 5.0 * t;
  dw[2] = -4.5 * t2 + 4.0 * t + 0.5;
  dw[3] = 1.5 * t2 - t;
}

}  // namespace

BicubicDistanceField::BicubicDistanceField(const LikelihoodField& field)
    : field_(field),
      cos_yaw_(std::cos(field.grid().origin().yaw)),
      sin_yaw_(std::sin(field.grid().origin().yaw)),
      inv_resolution_(1.0 / field.grid().resolution()),
      origin_x_(field.grid().origin().x),
      origin_y_(field.grid().origin().y),
      width_(field.grid().width()),
      height_(field.grid().height()) {}

FieldSample BicubicDistanceField::sample(double wx, double wy) const {
  const double c = cos_yaw_, s = sin_yaw_, inv_res = inv_resolution_;
  const double ox = wx - origin_x_, oy = wy - origin_y_;
  // Continuous cell coordinates in which cell centres are integers.
  const double gx = (c * ox + s * oy) * inv_res - 0.5;
  const double gy = (-s * ox + c * oy) * inv_res - 0.5;
  // Well off the map (or NaN): nothing there, as in the likelihood field.
  if (!(gx > -2.0 && gy > -2.0 && gx < width_ + 1.0 && gy < height_ + 1.0)) {
    return {field_.maxDistance(), 0.0, 0.0};
  }
  const int ix = static_cast<int>(std::floor(gx)), iy = static_cast<int>(std::floor(gy));
  double wxs[4], dwxs[4], wys[4], dwys[4];
  cubicWeights(gx - ix, wxs, dwxs);
  cubicWeights(gy - iy, wys, dwys);
  // A stencil that reaches past the map's edge repeats the edge cells.
  // max_distance there instead would be a cliff next to a wall on the edge,
  // which the cubic overshoots into negative distances, making false minima.
  const auto clamp = [](int v, int size) { return v < 0 ? 0 : (v >= size ? size - 1 : v); };
  int xs[4];
  for (int i = 0; i < 4; ++i) xs[i] = clamp(ix - 1 + i, width_);
  const float* d = field_.surfaceDistances().data();
  double value = 0.0, dgx = 0.0, dgy = 0.0;
  for (int j = 0; j < 4; ++j) {
    const float* row_cells = d + static_cast<std::size_t>(clamp(iy - 1 + j, height_)) * width_;
    double row = 0.0, drow = 0.0;
    for (int i = 0; i < 4; ++i) {
      const double v = row_cells[xs[i]];
      row += wxs[i] * v;
      drow += dwxs[i] * v;
    }
    value += wys[j] * row;
    dgx += wys[j] * drow;
    dgy += dwys[j] * row;
  }
  // d/d(world) = R(origin yaw) d/d(cell) / resolution.
  return {value, (c * dgx - s * dgy) * inv_res, (s * dgx + c * dgy) * inv_res};
}

}  // namespace pf

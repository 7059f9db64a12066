#include "pf_localization/sim/ray_caster.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pf::sim {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

double RayCaster::cast(double x, double y, double angle, double max_range) const {
  // Work in cell units of the grid's own frame, where cell (i, j) spans
  // [i, i + 1) x [j, j + 1).
  const double res = grid_.resolution();
  const Pose2 local = between(grid_.origin(), {x, y, angle});
  const double px = local.x / res, py = local.y / res;
  const double dx = std::cos(local.yaw), dy = std::sin(local.yaw);
  CellIndex c{static_cast<int>(std::floor(px)), static_cast<int>(std::floor(py))};
  if (!grid_.contains(c)) return kInf;
  if (grid_.state(c) == CellState::kOccupied) return 0.0;

  // t is the distance along the ray in cells; t_next_* is where it crosses
  // the next vertical / horizontal cell boundary, t_delta_* the distance
  // between two such crossings.
  const int step_x = dx > 0.0 ? 1 : -1;
  const int step_y = dy > 0.0 ? 1 : -1;
  double t_next_x = dx != 0.0 ? ((dx > 0.0 ? c.x + 1 : c.x) - px) / dx : kInf;
  double t_next_y = dy != 0.0 ? ((dy > 0.0 ? c.y + 1 : c.y) - py) / dy : kInf;
  const double t_delta_x = dx != 0.0 ? 1.0 / std::abs(dx) : kInf;
  const double t_delta_y = dy != 0.0 ? 1.0 / std::abs(dy) : kInf;
  const double t_limit = max_range / res;
  for (;;) {
    double t;
    if (t_next_x < t_next_y) {
      t = t_next_x;
      t_next_x += t_delta_x;
      c.x += step_x;
    } else {
      t = t_next_y;
      t_next_y += t_delta_y;
      c.y += step_y;
    }
    if (t > t_limit || !grid_.contains(c)) return kInf;
    if (grid_.state(c) == CellState::kOccupied) return t * res;
  }
}

double castToCircle(double x, double y, double angle, double cx, double cy, double r) {
  // |o + t d - c|^2 = r^2 with |d| = 1: t^2 - 2 b t + (|o - c|^2 - r^2) = 0.
  const double ox = x - cx, oy = y - cy;
  const double c = ox * ox + oy * oy - r * r;
  if (c <= 0.0) return kInf;  // inside: a sensor cannot see what it is in
  const double b = -(ox * std::cos(angle) + oy * std::sin(angle));
  const double disc = b * b - c;
  if (b <= 0.0 || disc < 0.0) return kInf;  // pointing away, or passing by
  return b - std::sqrt(disc);
}

std::vector<float> neatoReadings(const std::vector<double>& ideal, const NeatoLaserParams& params,
                                 SimRandom* random) {
  const std::size_t n = ideal.size();
  // How likely each beam is to be hidden by the robot itself.
  std::vector<double> blind(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double deg = 360.0 * i / n;
    for (const auto& [first, last] : params.blind_sectors) {
      if (deg >= first && deg <= last) {
        blind[i] = 1.0;
      } else if (deg >= first - 1.0 && deg <= last + 1.0) {
        blind[i] = std::max(blind[i], params.blind_edge);
      }
    }
  }

  std::vector<float> out(n, 0.0f);
  int burst_left = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (burst_left == 0 && random->uniform() < params.burst_rate) {
      // Geometric length with the given mean, at least one beam.
      const double p = 1.0 / params.burst_mean;
      burst_left =
          1 + static_cast<int>(std::floor(std::log(1.0 - random->uniform()) / std::log(1.0 - p)));
    }
    if (burst_left > 0) {
      --burst_left;
      continue;
    }
    if (blind[i] > 0.0 && random->uniform() < blind[i]) continue;
    double range = ideal[i];
    if (random->uniform() < params.short_rate) {
      range = random->uniform(params.range_min, std::min(range, params.range_max));
    }
    if (!(range < params.range_max)) continue;
    const double f = range / params.range_max;
    if (random->uniform() <
        params.dropout_near + (params.dropout_far - params.dropout_near) * f * f) {
      continue;
    }
    range += random->gaussian(params.sigma);
    range = std::round(range / params.resolution) * params.resolution;
    if (range < params.range_min || range >= params.range_max) continue;
    out[i] = static_cast<float>(range);
  }
  return out;
}

}  // namespace pf::sim

#include "pf_localization/core/likelihood_field_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pf {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("likelihood field model: " + what);
}

}  // namespace

LikelihoodFieldModel::LikelihoodFieldModel(const OccupancyGrid& grid,
                                           const LikelihoodFieldModelParams& params)
    : params_(params), field_(grid, params.max_distance) {
  require(params.z_hit >= 0.0 && std::isfinite(params.z_hit), "laser_z_hit must be >= 0");
  require(params.z_rand >= 0.0 && std::isfinite(params.z_rand), "laser_z_rand must be >= 0");
  require(params.z_hit + params.z_rand > 0.0, "laser_z_hit + laser_z_rand must be positive, got " +
                                                  std::to_string(params.z_hit + params.z_rand));
  require(params.sigma_hit > 0.0 && std::isfinite(params.sigma_hit),
          "laser_sigma_hit must be positive, got " + std::to_string(params.sigma_hit));
  require(params.likelihood_exponent > 0.0 && params.likelihood_exponent <= 1.0,
          "laser_likelihood_exponent must be in (0, 1], got " +
              std::to_string(params.likelihood_exponent));
  require(params.threads >= 1,
          "sensor_threads must be >= 1, got " + std::to_string(params.threads));
  require(params.max_beams >= 1,
          "laser_max_beams must be >= 1, got " + std::to_string(params.max_beams));
  require(params.range_min >= 0.0 && params.range_max >= 0.0,
          "laser_min_range and laser_max_range must be >= 0");
}

double LikelihoodFieldModel::beamLogLikelihood(double distance, double range_max) const {
  const double s = params_.sigma_hit;
  const double gauss = std::exp(-0.5 * distance * distance / (s * s)) / (s * std::sqrt(2.0 * M_PI));
  return std::log(params_.z_hit * gauss + params_.z_rand / range_max);
}

PreparedScan LikelihoodFieldModel::prepare(const LaserScan& scan, int max_beams) const {
  std::size_t valid = 0;
  const std::vector<Beam> beams =
      selectBeams(scan, max_beams, params_.range_min, params_.range_max, &valid);
  PreparedScan out;
  out.range_max =
      params_.range_max > 0.0 ? std::min(params_.range_max, scan.range_max) : scan.range_max;
  out.dropped = static_cast<int>(scan.ranges.size() - valid);
  out.x.reserve(beams.size());
  out.y.reserve(beams.size());
  for (const Beam& b : beams) {
    const Pose2 end = compose(scan.sensor_pose,
                              {b.range * std::cos(b.bearing), b.range * std::sin(b.bearing), 0.0});
    // Ranges of 1e38 m pass the scan's own limits when range_max is absurd;
    // in float cells they overflow, so they are dropped like any bad beam.
    const double res = field_.grid().resolution();
    if (!std::isfinite(static_cast<float>(end.x / res)) ||
        !std::isfinite(static_cast<float>(end.y / res))) {
      ++out.dropped;
      continue;
    }
    out.x.push_back(static_cast<float>(end.x));
    out.y.push_back(static_cast<float>(end.y));
  }
  return out;
}

void LikelihoodFieldModel::buildTable(double range_max) const {
  if (range_max == table_range_max_) return;
  const OccupancyGrid& grid = field_.grid();
  const int stride = grid.width() + 2;
  const double k = params_.likelihood_exponent;
  const float outside = static_cast<float>(k * beamLogLikelihood(field_.maxDistance(), range_max));
  table_.assign(static_cast<std::size_t>(stride) * (grid.height() + 2), outside);
  const std::vector<float>& dist = field_.distances();
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      table_[static_cast<std::size_t>(y + 1) * stride + x + 1] = static_cast<float>(
          k * beamLogLikelihood(dist[static_cast<std::size_t>(y) * grid.width() + x], range_max));
    }
  }
  table_range_max_ = range_max;
}

double LikelihoodFieldModel::hitFraction(const PreparedScan& scan, const Pose2& pose,
                                         double distance) const {
  if (scan.size() == 0) return 0.0;
  std::size_t hits = 0;
  for (std::size_t b = 0; b < scan.size(); ++b) {
    const Pose2 end = compose(pose, {scan.x[b], scan.y[b], 0.0});
    hits += field_.distanceAt(end.x, end.y) <= distance ? 1 : 0;
  }
  return static_cast<double>(hits) / static_cast<double>(scan.size());
}

double LikelihoodFieldModel::logLikelihood(const PreparedScan& scan, const Pose2& pose) const {
  ParticleSet one;
  one.resize(1);
  one.setPose(0, pose);
  std::vector<double> out;
  logLikelihoods(scan, one, &out);
  return out[0];
}

namespace {

// What scoring a particle needs, in the grid's cell units.
struct ScoringFrame {
  const float* table;  // per-cell log-likelihood with a one-cell border
  int stride;          // table width
  float max_x, max_y;  // last border column and row
  float inv_res;
  Pose2 origin;
  double origin_cos, origin_sin;
  const float* bx;  // beam end points in the robot frame, in cells
  const float* by;
  std::size_t beams;
};

// Scores particles [begin, end). Cloned for AVX2 next to the portable
// version: the beam loop vectorises, and the best clone is picked at load.
__attribute__((target_clones("avx2", "default"))) void scoreParticles(const ScoringFrame& f,
                                                                      const ParticleSet& particles,
                                                                      std::size_t begin,
                                                                      std::size_t end,
                                                                      double* out) {
  // Locals, not the frame's fields: the compiler can then prove that the
  // stores to `out` change none of them, and vectorises the beam loop.
  const float* table = f.table;
  const int stride = f.stride;
  const float max_x = f.max_x, max_y = f.max_y;
  const float* bx = f.bx;
  const float* by = f.by;
  const std::size_t beams = f.beams;
  for (std::size_t i = begin; i < end; ++i) {
    // The particle in the grid's frame, in cells, shifted by the border; the
    // origin's rotation is applied here, once per particle.
    const double dx = particles.x[i] - f.origin.x, dy = particles.y[i] - f.origin.y;
    const float px = static_cast<float>((f.origin_cos * dx + f.origin_sin * dy) * f.inv_res) + 1.0f;
    const float py =
        static_cast<float>((-f.origin_sin * dx + f.origin_cos * dy) * f.inv_res) + 1.0f;
    const float yaw = static_cast<float>(particles.yaw[i] - f.origin.yaw);
    const float c = std::cos(yaw);
    const float s = std::sin(yaw);
    float sum = 0.0f;
    for (std::size_t b = 0; b < beams; ++b) {
      // Clamping before truncation sends every point outside the map to the
      // border, and makes truncation equal floor for what remains. The
      // comparisons are written so that NaN (from a particle at infinity)
      // also lands in the border instead of becoming an undefined int.
      const float ex = px + c * bx[b] - s * by[b];
      const float ey = py + s * bx[b] + c * by[b];
      const float gx = ex > 0.0f ? std::min(ex, max_x) : 0.0f;
      const float gy = ey > 0.0f ? std::min(ey, max_y) : 0.0f;
      sum += table[static_cast<int>(gy) * stride + static_cast<int>(gx)];
    }
    out[i] = sum;
  }
}

}  // namespace

void LikelihoodFieldModel::logLikelihoods(const PreparedScan& scan, const ParticleSet& particles,
                                          std::vector<double>* log_likelihood) const {
  buildTable(scan.range_max);
  const OccupancyGrid& grid = field_.grid();
  const float inv_res = static_cast<float>(1.0 / grid.resolution());
  // End points in cell units, so the inner loop needs no division.
  const std::size_t n = scan.size();
  std::vector<float> bx(n), by(n);
  for (std::size_t b = 0; b < n; ++b) {
    bx[b] = scan.x[b] * inv_res;
    by[b] = scan.y[b] * inv_res;
  }
  const ScoringFrame frame{table_.data(),
                           grid.width() + 2,
                           static_cast<float>(grid.width() + 1),
                           static_cast<float>(grid.height() + 1),
                           inv_res,
                           grid.origin(),
                           std::cos(grid.origin().yaw),
                           std::sin(grid.origin().yaw),
                           bx.data(),
                           by.data(),
                           n};
  log_likelihood->resize(particles.size());
  const int threads = params_.threads;
  if (threads <= 1) {
    scoreParticles(frame, particles, 0, particles.size(), log_likelihood->data());
    return;
  }
  // One contiguous slice per thread; every particle's score is computed
  // alone, so the result is the same for any thread count.
#ifdef _OPENMP
#pragma omp parallel for num_threads(threads) schedule(static)
#endif
  for (int t = 0; t < threads; ++t) {
    const std::size_t size = particles.size();
    scoreParticles(frame, particles, size * t / threads, size * (t + 1) / threads,
                   log_likelihood->data());
  }
}

}  // namespace pf

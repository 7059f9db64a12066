#include "pf_localization/core/recovery/global_search.h"

#include <algorithm>
#include <cmath>

namespace pf {

double searchSmoothing(double particles, double support, double range) {
  if (particles <= 0.0 || support <= 0.0) return 0.0;
  // The volume of poses within reach, 4 s^2 * min(2 s / r, 2 pi), must hold
  // kParticlesInReach of the particles: support / particles each.
  const double volume = kParticlesInReach * support / particles;
  const double r = std::max(range, 0.0);
  const double s = std::cbrt(volume * r / 8.0);
  // Beyond s = pi r every heading is within reach.
  if (s <= M_PI * r) return s;
  return std::sqrt(volume / (8.0 * M_PI));
}

double supportOfBins(double bins, double particles, double bin_volume, double max_support) {
  const double max_bins = max_support / bin_volume;
  const auto occupied = [particles](double b) { return b * -std::expm1(-particles / b); };
  // Every particle in a bin of its own: the bins say nothing of the spacing.
  if (bins >= particles || occupied(max_bins) <= bins) return max_support;
  double lo = bins, hi = max_bins;  // occupied() grows with B from bins(ish) to particles
  for (int i = 0; i < 60 && hi - lo > 1e-6 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (occupied(mid) < bins ? lo : hi) = mid;
  }
  return std::min(0.5 * (lo + hi) * bin_volume, max_support);
}

void GlobalSearch::start(double free_area) {
  phase_ = Phase::kSmoothing;
  max_support_ = free_area * 2.0 * M_PI;
  sigma_ = 0.0;
}

const SensorModel* GlobalSearch::model(const SensorModel& model, double sigma_hit,
                                       double max_distance, const std::vector<PreparedScan>& scans,
                                       const ParticleSet& particles, const KldParams& kld,
                                       int threads) {
  sigma_ = 0.0;
  if (phase_ != Phase::kSmoothing) return nullptr;
  ranges_.clear();
  for (const PreparedScan& scan : scans) {
    ranges_.insert(ranges_.end(), scan.range.begin(), scan.range.end());
  }
  if (ranges_.empty()) return nullptr;  // nothing to weigh by: the search goes on
  const auto median = ranges_.begin() + static_cast<std::ptrdiff_t>(ranges_.size() / 2);
  std::nth_element(ranges_.begin(), median, ranges_.end());

  const double n = static_cast<double>(particles.size());
  const double bins = static_cast<double>(occupiedBins(particles, kld, threads));
  const double support =
      supportOfBins(bins, n, kld.bin_xy * kld.bin_xy * kld.bin_yaw, max_support_);
  const double s = searchSmoothing(n, support, *median);
  // The level: sigma_hit times a power of sqrt(2), at least s.
  const double level = sigma_hit * std::exp2(0.5 * std::ceil(2.0 * std::log2(s / sigma_hit)));
  if (s <= sigma_hit || level > kMaxSearchSmoothing * max_distance) {
    // Dense enough for the model, or too sparse for any smoothing that
    // keeps the map's contrast: the model's own, for good.
    settle();
    return nullptr;
  }
  if (!smoothed_ || smoothed_sigma_ != level) {
    smoothed_ = model.smoothed(level);
    smoothed_sigma_ = level;
  }
  if (!smoothed_) {
    settle();  // a model without a hit component to widen
    return nullptr;
  }
  sigma_ = level;
  return smoothed_.get();
}

}  // namespace pf

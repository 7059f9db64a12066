// Global localization's smoothed likelihood: while the cloud of a global
// initialisation is too sparse for the sensor model's sharp likelihood, the
// particles are weighed by a wider one.
//
// Pfaff, Burgard & Fox, "Robust Monte-Carlo localization using adaptive
// likelihood models" (EUROS 2006): a particle stands for the poses around
// it, so its weight should be the likelihood over that region, and a sparse
// cloud needs a smoother likelihood than a dense one. Otherwise the place
// whose luckiest particle happens to fit best takes all the weight, and
// look-alike places (twin rooms, the aisles of a warehouse) vanish before
// their particles could converge.
//
// Here the smoothing is the hit component's std dev s, one for the whole
// cloud, from its density. N particles over a support of V (m^2 rad) put on
// average N * 4 s^2 * min(2 s / r, 2 pi) / V of them within s of any pose in
// x and y and within s / r in heading, r being the scan's median range (so
// that the end points move by about s at most). s is the smallest width that
// puts kParticlesInReach there. The support V is the cloud's occupied bins of
// KLD-sampling's histogram, corrected for the bins that hold several
// particles, at most the map's free space times 2 pi.
//
// s is rounded up to sigma_hit times a power of sqrt(2), so that a new table
// is built only when that level changes, a few times per search. Once s falls
// to sigma_hit the cloud is dense enough for the model itself, which takes
// over for good. The smoothing ends too, leaving the model's likelihood as it
// is, when the cloud is too sparse for a smoothing that keeps the map's
// contrast (kMaxSearchSmoothing): a budget of particles too small for the map.
//
// Then the cloud settles: until it holds one place (hypotheses.h), a scan is
// tempered to leave at least kSettlingEssFraction of the effective sample,
// so that the look-alike places the smoothing kept are not decided by noise.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/core/sensor/sensor_model.h"

namespace pf {

/// Particles that should fall within reach of every place the robot could
/// be: a Poisson count with this mean misses a place with probability
/// e^-5 = 0.7 %, so that of a hundred look-alike places one at most starts
/// without a particle near enough to be weighed fairly.
inline constexpr double kParticlesInReach = 5.0;

/// The widest smoothing, as a share of laser_likelihood_max_dist (the
/// distance beyond which every end point is equally unlikely): an end point
/// that far from a wall must stay 3 std devs off, e^-4.5 = 1 % as likely as
/// one on it. A wider likelihood is nearly flat, and weighs the cloud by the
/// map's open space more than by the scan.
inline constexpr double kMaxSearchSmoothing = 1.0 / 3.0;

/// The smoothing std dev (m) for `particles` particles over a support of
/// `support` (m^2 rad), seen by a scan of median range `range` (m).
double searchSmoothing(double particles, double support, double range);

/// The support (m^2 rad) of `particles` particles that occupy `bins` bins of
/// `bin_volume` (m^2 rad), at most `max_support`: the bins B with
/// B (1 - e^(-particles / B)) = bins, the count of occupied bins expected of
/// particles spread uniformly over B.
double supportOfBins(double bins, double particles, double bin_volume, double max_support);

/// While a global initialisation's cloud settles after the smoothing, a scan
/// may leave no fewer than this share of its effective particles (tempering,
/// weighting.h): among look-alike places the differences between their fits
/// are noise (unmapped pallets, where each place's particles happen to lie),
/// so the evidence must come from several scans. Half, resample_ess_fraction:
/// no single scan makes the cloud resample. Until one place is left: within
/// one place the floor would only keep the cloud wide. The evidence:
/// docs/design.md, "A sparse cloud is weighed by a wider likelihood".
inline constexpr double kSettlingEssFraction = kResampleEssFraction;

class GlobalSearch {
 public:
  /// Starts a search over `free_area` m^2 of free space (a global initialisation).
  void start(double free_area);
  /// Ends the search (an initialisation at a pose).
  void stop() { phase_ = Phase::kDone; }
  /// Whether the cloud is still weighed by a smoothed likelihood.
  bool smoothing() const { return phase_ == Phase::kSmoothing; }
  /// Drops the smoothed model (the sensor model or its map was replaced).
  void forgetModel() { smoothed_.reset(); }

  /// The model to weigh `particles` by `scans` with: a smoothed copy of
  /// `model` (whose hit std dev is `sigma_hit`, its distance cap
  /// `max_distance`) while smoothing and the cloud too sparse for `model`;
  /// null otherwise. A cloud dense enough ends the smoothing, as do one too
  /// sparse for kMaxSearchSmoothing and a model with no smoothed form: the
  /// cloud then settles.
  const SensorModel* model(const SensorModel& model, double sigma_hit, double max_distance,
                           const std::vector<PreparedScan>& scans, const ParticleSet& particles,
                           const KldParams& kld, int threads);
  /// The std dev of the last smoothed model model() returned, 0 after it
  /// returned null.
  double sigma() const { return sigma_; }

  /// The least share of the effective sample a scan may leave:
  /// kSettlingEssFraction while the cloud settles, 0 otherwise.
  double minEssFraction() const { return phase_ == Phase::kSettling ? kSettlingEssFraction : 0.0; }
  /// Takes the number of places the update's cloud holds (hypotheses.h):
  /// one ends the settling.
  void observe(std::size_t places) {
    if (phase_ == Phase::kSettling && places <= 1) phase_ = Phase::kDone;
  }

 private:
  enum class Phase { kSmoothing, kSettling, kDone };
  void settle() {
    phase_ = Phase::kSettling;
    smoothed_.reset();
  }

  Phase phase_ = Phase::kDone;
  double max_support_ = 0.0;  // m^2 rad: the free space times 2 pi
  double sigma_ = 0.0;
  std::unique_ptr<SensorModel> smoothed_;
  double smoothed_sigma_ = 0.0;
  std::vector<float> ranges_;  // scratch for the median
};

}  // namespace pf

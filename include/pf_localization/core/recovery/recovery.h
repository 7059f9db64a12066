// Recovery from a lost or wrong track: after each scan, how many random
// particles the resampling injects and whether it spreads the survivors,
// from the fit of the scans and the confidence state. Each scheme is a
// RecoveryStrategy; Recovery combines them (the largest injection wins) and
// resamples by the plan.
//
// - AugmentedMclInjection: Thrun, Burgard & Fox, "Probabilistic Robotics"
//   (2005), table 8.3: a short-term average of the mean beam likelihood below
//   trigger_ratio times the long-term one injects that dip's share; unless
//   lost, only after the fit stayed low for more than `patience` updates
//   (patience_localized while localized). Updates closer together than a
//   view (view_share.h) count their share of it, inject that share of the dip,
//   and move the averages by it.
// - LostShareInjection: a compact cloud that is lost searches at once with
//   lost_share of max_particles.
// - ExpansionResetting: Ueda et al., "Expansion resetting for recovery from
//   fatal error in Monte Carlo localization" (IROS 2004): a single scan
//   fitting below expansion_ratio times the long-term average spreads the
//   survivors of the resampling.
// - LookAlikeMove: where the scan fits look-alikes of the estimate clearly
//   better (look_alikes.h), each gets a copy of the survivors carried there
//   by the map's motion, keeping the cloud's shape: the twin a robot was
//   kidnapped into, or the one a global search missed, is tried at once.
// Injected particles weigh kidnap_prior together (a mixture proposal: Thrun,
// Fox, Burgard & Dellaert, AIJ 128, 2001). See docs/design.md, "Recovery
// waits while localized".
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/util/pose2.h"
#include "pf_localization/core/util/random.h"

namespace pf {

/// What the strategies see after a scan was weighed and judged.
struct RecoveryContext {
  double mean_beam_likelihood = 0.0;                   // this scan's (SensorUpdate::weigh)
  double slow_before = 0.0;                            // the long-term average before this scan
  double slow = 0.0;                                   // the long-term average, this scan included
  double fast = 0.0;                                   // the short-term average, this scan included
  LocalizationState state = LocalizationState::kLost;  // this scan's verdict
  std::size_t particles = 0;                           // in the cloud now
  std::size_t max_particles = 0;                       // the budget (kld.max_particles)
  double view = 1.0;                      // the share of a new view this scan brings (view_share.h)
  bool has_free_space = false;            // the map has free cells to draw random particles from
  std::vector<Pose2> better_look_alikes;  // map motions to look-alikes the scan fits clearly better
};

/// What the resampling is to do.
struct RecoveryPlan {
  double inject_probability = 0.0;  // share of max_particles drawn at random
  bool spread = false;              // spread the survivors (expansion resetting)
  double spread_scale = 1.0;        // times expansion_std_xy and expansion_std_yaw
  std::vector<Pose2> moves;         // map motions a share of the survivors take (LookAlikeMove)
};

class RecoveryStrategy {
 public:
  virtual ~RecoveryStrategy() = default;
  /// Adds this scheme's say to `plan` (raising inject_probability, setting
  /// spread). Called once per update.
  virtual void contribute(const RecoveryContext& context, const RecoveryParams& params,
                          RecoveryPlan* plan) = 0;
  /// Forgets the history (after an initialisation).
  virtual void restart() {}
};

class AugmentedMclInjection final : public RecoveryStrategy {
 public:
  void contribute(const RecoveryContext& context, const RecoveryParams& params,
                  RecoveryPlan* plan) override;
  void restart() override { low_fit_views_ = 0.0; }
  /// The new views (view_share.h) the consecutive updates so far with the
  /// short-term average below the trigger brought; with the default
  /// thresholds, their count.
  double lowFitViews() const { return low_fit_views_; }

 private:
  double low_fit_views_ = 0.0;
};

class LostShareInjection final : public RecoveryStrategy {
 public:
  void contribute(const RecoveryContext& context, const RecoveryParams& params,
                  RecoveryPlan* plan) override;
};

class ExpansionResetting final : public RecoveryStrategy {
 public:
  void contribute(const RecoveryContext& context, const RecoveryParams& params,
                  RecoveryPlan* plan) override;
  /// Spreads the first `n` particles by expansion_std_xy / expansion_std_yaw
  /// times `scale` (x, y, yaw from `random`, particle by particle).
  static void spread(const RecoveryParams& params, std::size_t n, Random* random,
                     ParticleSet* particles, double scale = 1.0);
};

class LookAlikeMove final : public RecoveryStrategy {
 public:
  void contribute(const RecoveryContext& context, const RecoveryParams& params,
                  RecoveryPlan* plan) override;
  /// Appends to the first `n` particles, for each motion, a copy of them
  /// moved by it; when the cloud would outgrow `room` particles, each copy
  /// takes an equal share of the room left, spread over the survivors.
  /// Returns how many were added. The tracked place keeps all of its
  /// particles, should the look-alikes' lead be noise, and each look-alike
  /// is as densely sampled as it: with a share each (half the survivors
  /// split among them), a look-alike's weight was that of its luckiest few
  /// particles, and a twin as likely as the others could lose them all on
  /// the next scan (docs/design.md, "Look-alike places").
  static std::size_t copy(const std::vector<Pose2>& moves, std::size_t n, std::size_t room,
                          ParticleSet* particles);
};

/// What Recovery::resample did.
struct ResampleOutcome {
  bool resampled = false;
  std::size_t injected = 0;  // random particles added
  bool expanded = false;     // the survivors were spread
  std::size_t moved = 0;     // particles added at look-alikes (LookAlikeMove::copy)
};

class Recovery {
 public:
  /// Forgets the averages and the strategies' history (after an initialisation).
  void restart();

  /// Takes this scan's mean beam likelihood into the averages (alpha_slow,
  /// alpha_fast; alpha_slow 0 keeps them at 0, which disables recovery), at
  /// their rates times `view`, the share of a new view the scan brings
  /// (view_share.h): the averages, the patience, the injected share and the
  /// spread of the next plan() are per view, not per update.
  void observe(double mean_beam_likelihood, const RecoveryParams& params, double view = 1.0);
  /// The plan for this update, from the last observe() and this scan's
  /// verdict `state`, for a cloud of `particles` with the budget
  /// `max_particles`.
  RecoveryPlan plan(LocalizationState state, std::size_t particles, std::size_t max_particles,
                    bool has_free_space, const RecoveryParams& params);
  /// The look-alikes this scan fits clearly better, for the next plan().
  void observeLookAlikes(std::vector<Pose2> better) {
    context_.better_look_alikes = std::move(better);
  }
  /// The views of the consecutive updates with a fit below the trigger
  /// (AugmentedMclInjection).
  double lowFitViews() const { return injection_.lowFitViews(); }

  /// Resamples `particles` by `plan` when their effective sample size `ess`
  /// is below resample_ess_fraction of their count or the plan asks for
  /// anything: KLD-sampling (Fox 2003) picks the count, systematic
  /// resampling the survivors, and the injected share comes from
  /// randomFreePose on `grid`. Draws from `random`: the injected count, the
  /// resampling, the spread, the injected poses. KLD's bins and the
  /// resampling run on up to `threads` threads (the same for any count).
  ResampleOutcome resample(const RecoveryPlan& plan, double ess, const ParticleFilterParams& params,
                           const OccupancyGrid& grid, Random* random, ParticleSet* particles,
                           int threads = 1);

  /// Prefaults the resampler's output for `n` particles.
  void reserve(std::size_t n);

 private:
  RecoveryContext context_;  // of the last observe()
  AugmentedMclInjection injection_;
  LostShareInjection lost_share_;
  ExpansionResetting expansion_;
  LookAlikeMove look_alike_move_;
  ParticleSet spare_;  // the resampler's output, swapped with the cloud
};

// A pose drawn uniformly over a map's free space: the particles of a global
// localization and the random guesses recovery injects (Thrun et al.,
// "Probabilistic Robotics", table 8.3).
/// A free cell of `grid` chosen uniformly, a point uniformly inside it and a
/// uniform yaw in [-pi, pi), in the map frame, drawn from `random` in that
/// order. Precondition: grid.freeCells() is not empty.
Pose2 randomFreePose(const OccupancyGrid& grid, Random* random);

}  // namespace pf

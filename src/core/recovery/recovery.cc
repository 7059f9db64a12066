#include "pf_localization/core/recovery/recovery.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/core/filter/view_share.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {

void AugmentedMclInjection::contribute(const RecoveryContext& context, const RecoveryParams& params,
                                       RecoveryPlan* plan) {
  // Dips of a few tenths come and go in normal tracking (a person in front
  // of the laser, a doorway); only a fit below trigger_ratio times the usual
  // one injects anything.
  const double usual = params.trigger_ratio * context.slow;
  const double dip = usual > 0.0 ? std::max(0.0, 1.0 - context.fast / usual) : 0.0;
  low_fit_views_ = dip > 0.0 ? low_fit_views_ + context.view : 0.0;
  // The fit sags for a few scans wherever the map is poor, and random
  // guesses then only add rivals; a robot really lost is soon "lost", or
  // stays badly fitted for longer.
  const int patience =
      context.state == LocalizationState::kLocalized ? params.patience_localized : params.patience;
  const bool patient =
      context.state != LocalizationState::kLost && !moreViewsThan(low_fit_views_, patience);
  // A view's worth of closer updates injects what one update would.
  if (context.has_free_space && !patient) {
    plan->inject_probability = std::max(plan->inject_probability, dip * context.view);
  }
}

void LostShareInjection::contribute(const RecoveryContext& context, const RecoveryParams& params,
                                    RecoveryPlan* plan) {
  // Not while the cloud already holds more than (1 - lost_share) of the
  // budget: it is searching (a global localization), and halving it would
  // only thin the search.
  const bool compact_and_lost =
      context.state == LocalizationState::kLost &&
      static_cast<double>(context.particles) <=
          (1.0 - params.lost_share) * static_cast<double>(context.max_particles);
  if (context.has_free_space && compact_and_lost) {
    plan->inject_probability = std::max(plan->inject_probability, params.lost_share);
  }
}

void ExpansionResetting::contribute(const RecoveryContext& context, const RecoveryParams& params,
                                    RecoveryPlan* plan) {
  // One scan fitting far worse than usual: the robot has probably slipped or
  // been pushed a little, and spreading the survivors finds it nearby long
  // before random particles would.
  if (params.expansion_ratio > 0.0 && context.slow_before > 0.0 &&
      context.mean_beam_likelihood < params.expansion_ratio * context.slow_before) {
    plan->spread = true;
    // The spreads of a view's worth of closer updates add up to one's.
    plan->spread_scale = std::sqrt(context.view);
  }
}

void ExpansionResetting::spread(const RecoveryParams& params, std::size_t n, Random* random,
                                ParticleSet* particles, double scale) {
  const double std_xy = params.expansion_std_xy * scale;
  const double std_yaw = params.expansion_std_yaw * scale;
  for (std::size_t i = 0; i < n; ++i) {
    particles->x[i] += random->gaussian(std_xy);
    particles->y[i] += random->gaussian(std_xy);
    particles->yaw[i] = normalizeAngle(particles->yaw[i] + random->gaussian(std_yaw));
  }
}

void LookAlikeMove::contribute(const RecoveryContext& context, const RecoveryParams& /*params*/,
                               RecoveryPlan* plan) {
  // Whenever a look-alike has fitted clearly better for kBetterUpdates in a
  // row (look_alikes.h): that streak is what tells a place from an object
  // that is not on the map. Asking as well for a fit below the usual one
  // held the move back for seconds where the fit sinks slowly, as the view
  // that tells two aisles apart comes in (docs/design.md).
  plan->moves = context.better_look_alikes;
}

std::size_t LookAlikeMove::copy(const std::vector<Pose2>& moves, std::size_t n, std::size_t room,
                                ParticleSet* particles) {
  if (moves.empty() || n == 0 || room <= n) return 0;
  const std::size_t each = std::min(n, (room - n) / moves.size());
  particles->resize(n + each * moves.size());
  std::size_t to = n;
  for (const Pose2& motion : moves) {
    for (std::size_t j = 0; j < each; ++j) {
      const std::size_t from = j * n / each;
      particles->setPose(to++, compose(motion, particles->pose(from)));
    }
  }
  return to - n;
}

void Recovery::restart() {
  context_.slow = context_.fast = 0.0;
  context_.better_look_alikes.clear();
  injection_.restart();
  lost_share_.restart();
  expansion_.restart();
}

void Recovery::observe(double mean_beam_likelihood, const RecoveryParams& params, double view) {
  context_.mean_beam_likelihood = mean_beam_likelihood;
  context_.view = view;
  context_.slow_before = context_.slow;
  if (params.alpha_slow > 0.0) {
    if (context_.slow == 0.0) {
      context_.slow = context_.fast = mean_beam_likelihood;
    } else {
      context_.slow += view * params.alpha_slow * (mean_beam_likelihood - context_.slow);
      context_.fast += view * params.alpha_fast * (mean_beam_likelihood - context_.fast);
    }
  }
}

RecoveryPlan Recovery::plan(LocalizationState state, std::size_t particles,
                            std::size_t max_particles, bool has_free_space,
                            const RecoveryParams& params) {
  context_.state = state;
  context_.particles = particles;
  context_.max_particles = max_particles;
  context_.has_free_space = has_free_space;
  RecoveryPlan plan;
  for (RecoveryStrategy* strategy :
       {static_cast<RecoveryStrategy*>(&injection_), static_cast<RecoveryStrategy*>(&lost_share_),
        static_cast<RecoveryStrategy*>(&expansion_),
        static_cast<RecoveryStrategy*>(&look_alike_move_)}) {
    strategy->contribute(context_, params, &plan);
  }
  return plan;
}

ResampleOutcome Recovery::resample(const RecoveryPlan& plan, double ess,
                                   const ParticleFilterParams& params, const OccupancyGrid& grid,
                                   Random* random, ParticleSet* particles, int threads) {
  ResampleOutcome out;
  const std::size_t n = particles->size();
  const double p = plan.inject_probability;
  if (ess >= params.resample_ess_fraction * n && p < 0.01 && !plan.spread && plan.moves.empty()) {
    return out;
  }

  const std::size_t target = kldParticleCount(*particles, params.kld, threads);
  // Random particles are spread over the whole map, so they are counted
  // against the largest cloud, not the converged one: a lost filter must
  // search with as many particles as a global localization.
  const std::size_t max = static_cast<std::size_t>(params.kld.max_particles);
  const auto injected =
      std::min(max, static_cast<std::size_t>(std::floor(p * max + random->uniform())));
  const std::size_t kept =
      std::min(max - injected, static_cast<std::size_t>(std::ceil((1.0 - p) * target)));
  systematicResample(*particles, kept, random, &spare_, threads);
  std::swap(*particles, spare_);
  if (plan.spread) {
    ExpansionResetting::spread(params.recovery, kept, random, particles, plan.spread_scale);
  }
  const std::size_t copied = LookAlikeMove::copy(plan.moves, kept, max - injected, particles);
  out.moved = copied;
  const std::size_t survivors = kept + copied;
  particles->resize(survivors + injected);
  for (std::size_t i = survivors; i < survivors + injected; ++i) {
    particles->setPose(i, randomFreePose(grid, random));
  }
  particles->setUniformWeights();
  if (injected > 0 && survivors > 0) {
    const double prior = params.recovery.kidnap_prior;
    const double w_kept = (1.0 - prior) / static_cast<double>(survivors);
    const double w_injected = prior / static_cast<double>(injected);
    std::fill(particles->weight.begin(), particles->weight.begin() + survivors, w_kept);
    std::fill(particles->weight.begin() + survivors, particles->weight.end(), w_injected);
  }
  out.resampled = true;
  out.injected = injected;
  out.expanded = plan.spread;
  return out;
}

void Recovery::reserve(std::size_t n) {
  for (std::vector<double>* v : {&spare_.x, &spare_.y, &spare_.yaw, &spare_.weight}) {
    prefault(v, n);
  }
}

Pose2 randomFreePose(const OccupancyGrid& grid, Random* random) {
  const FreeCells& free = grid.freeCells();
  const int cell = free[random->index(free.size())];
  const CellIndex c = grid.cellOf(cell);
  // Anywhere inside the cell, not only its centre.
  const Pose2 local{(c.x + random->uniform()) * grid.resolution(),
                    (c.y + random->uniform()) * grid.resolution(), random->uniform(-M_PI, M_PI)};
  return compose(grid.origin(), local);
}

}  // namespace pf

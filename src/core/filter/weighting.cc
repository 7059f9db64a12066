#include "pf_localization/core/filter/weighting.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/util/fast_math.h"

namespace pf {
namespace {

// Every loop below over the particles is split over `threads`: the
// element-wise ones in even slices, the sums and maxima block by block
// (particle_blocks.h), so that the weights are the same bits for any count.

// A running sum and sum of squares.
struct Sums {
  double sum = 0.0, sum_sq = 0.0;
};
void mergeSums(Sums& into, const Sums& from) {
  into.sum += from.sum;
  into.sum_sq += from.sum_sq;
}

// The sum and sum of squares of v.
Sums sums(const std::vector<double>& v, int threads) {
  return reduceBlocks(
      v.size(), threads, Sums(),
      [&](std::size_t i, Sums& a) {
        a.sum += v[i];
        a.sum_sq += v[i] * v[i];
      },
      mergeSums);
}

// The largest of v(i) over [0, n) (-inf for none).
template <typename Value>
double maxBlocks(std::size_t n, int threads, Value&& v) {
  return reduceBlocks(
      n, threads, -std::numeric_limits<double>::infinity(),
      [&](std::size_t i, double& m) { m = std::max(m, v(i)); },
      [](double& into, double from) { into = std::max(into, from); });
}

// f(i) for every i in [0, n), in slices.
template <typename F>
void forEachParticle(std::size_t n, int threads, F&& f) {
  forEachSlice(n, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) f(i);
  });
}

// Calls add(i, exp(x(i))) for each i in [begin, end) in turn, the
// exponentials taken a chunk at a time in cache (exps vectorises) rather
// than written for the whole cloud and read back in another pass.
template <typename X, typename Add>
void addExps(std::size_t begin, std::size_t end, X x, Add add) {
  constexpr std::size_t kChunk = 1024;
  double e[kChunk];
  for (std::size_t from = begin; from < end; from += kChunk) {
    const std::size_t len = std::min(kChunk, end - from);
    for (std::size_t j = 0; j < len; ++j) e[j] = x(from + j);
    exps(e, len, e);
    for (std::size_t j = 0; j < len; ++j) add(from + j, e[j]);
  }
}

// The log prior of every particle, without storing a uniform prior's: a
// constant prior does not change the normalised result, and zeros spare N
// logarithms, N stores and a read of them in every pass.
struct ZeroLogPrior {
  static constexpr bool kUniform = true;
  double operator()(std::size_t) const { return 0.0; }
};
struct StoredLogPrior {
  static constexpr bool kUniform = false;
  const double* log_prior;
  double operator()(std::size_t i) const { return log_prior[i]; }
};

// ESS of the weights prior * likelihood^beta (beta > 0), from their
// logarithms; max_ll is the largest log likelihood. The weights are made,
// exponentiated and summed a chunk at a time (addExps) instead of in three
// passes over the cloud: the tempering's bisection takes twenty of these.
// The sums are the same, in the same order.
//
// With a uniform prior the largest log weight is beta * max_ll without a
// pass over the cloud: rounding is monotone, so the largest rounded
// beta * ll is beta * max_ll rounded (and 0 + x is x but for the sign of a
// zero, which the weights do not see). The same ESS, bit for bit.
template <typename LogPrior>
double effectiveSampleSize(LogPrior log_prior, const std::vector<double>& log_likelihood,
                           double beta, double max_ll, int threads) {
  const std::size_t n = log_likelihood.size();
  const double max_log =
      LogPrior::kUniform ? beta * max_ll : maxBlocks(n, threads, [&](std::size_t i) {
        return log_prior(i) + beta * log_likelihood[i];
      });
  if (!std::isfinite(max_log)) return 0.0;
  const Sums s = reduceBlockRanges(
      n, threads, Sums(),
      [&](std::size_t begin, std::size_t end, Sums& a) {
        addExps(
            begin, end,
            [&](std::size_t i) { return log_prior(i) + beta * log_likelihood[i] - max_log; },
            [&](std::size_t, double w) {
              a.sum += w;
              a.sum_sq += w * w;
            });
      },
      mergeSums);
  return s.sum * s.sum / s.sum_sq;
}

// The prior's effective sample size: after a resampling every weight is the
// same, and it is then N; otherwise it comes from the weights themselves,
// (sum w)^2 / sum w^2, without exponentials.
double priorEffectiveSampleSize(const std::vector<double>& w, bool uniform, int threads) {
  double prior_ess = static_cast<double>(w.size());
  if (!uniform) {
    const Sums s = sums(w, threads);
    prior_ess = s.sum_sq > 0.0 ? s.sum * s.sum / s.sum_sq : 0.0;
  }
  return prior_ess;
}

// Nearly always the product prior * likelihood / max likelihood can be
// taken as it is, without a logarithm per particle: when the best product
// is far from underflowing and the scan needs no tempering. Then writes
// the normalised posterior into *weights and returns true; *posterior is
// working storage of N values.
bool multiplyDirectly(const std::vector<double>& ll, double min_ess, std::vector<double>* weights,
                      std::vector<double>* posterior, int threads) {
  double* w = weights->data();
  double* e = posterior->data();
  const std::size_t n = weights->size();
  const double max_ll = maxBlocks(ll.size(), threads, [&](std::size_t i) { return ll[i]; });
  if (!std::isfinite(max_ll)) return false;
  struct Product {
    double total = 0.0, total_sq = 0.0, peak = 0.0;
  };
  // The exponentials, the products and their sums in one pass (addExps).
  const Product p = reduceBlockRanges(
      n, threads, Product(),
      [&](std::size_t begin, std::size_t end, Product& a) {
        addExps(
            begin, end, [&](std::size_t i) { return ll[i] - max_ll; },
            [&](std::size_t i, double likelihood) {
              e[i] = likelihood * w[i];
              a.total += e[i];
              a.total_sq += e[i] * e[i];
              a.peak = std::max(a.peak, e[i]);
            });
      },
      [](Product& into, const Product& from) {
        into.total += from.total;
        into.total_sq += from.total_sq;
        into.peak = std::max(into.peak, from.peak);
      });
  if (p.peak > 1e-100 && !(min_ess > 0.0 && p.total * p.total / p.total_sq < min_ess)) {
    forEachParticle(n, threads, [&](std::size_t i) { w[i] = e[i] / p.total; });
    return true;
  }
  return false;
}

// The logarithms of a prior that is not uniform.
void logPrior(const std::vector<double>& w, std::vector<double>* log_prior, int threads) {
  log_prior->resize(w.size());
  double* lp = log_prior->data();
  forEachParticle(w.size(), threads, [&](std::size_t i) { lp[i] = std::log(w[i]); });
}

// The untempered posterior, in one pass of exponentials that serves both
// the tempering test and (nearly always) the result: *posterior holds
// prior * likelihood / max, *total its sum. Returns the log of the max, and
// its effective sample size in *ess.
template <typename LogPrior>
double untemperedPosterior(LogPrior log_prior, const std::vector<double>& ll,
                           std::vector<double>* posterior, double* total_out, double* ess,
                           int threads) {
  double* e = posterior->data();
  const std::size_t n = posterior->size();
  const double max_log = maxBlocks(n, threads, [&](std::size_t i) {
    e[i] = log_prior(i) + ll[i];
    return e[i];
  });
  // When every particle scores zero (possible with z_rand = 0: an end point
  // far from any obstacle has likelihood exp(-800) = 0), max_log is -inf and
  // normalising would give 0/0 = NaN weights, which the resampler collapses
  // onto particle 0. Evidence that rules out all particles alike favours
  // none: the caller leaves the weights as they were.
  Sums s;
  if (std::isfinite(max_log)) {
    // The exponentials and their sums in one pass (addExps).
    s = reduceBlockRanges(
        n, threads, Sums(),
        [&](std::size_t begin, std::size_t end, Sums& a) {
          addExps(
              begin, end, [&](std::size_t i) { return e[i] - max_log; },
              [&](std::size_t i, double v) {
                e[i] = v;
                a.sum += v;
                a.sum_sq += v * v;
              });
        },
        mergeSums);
  }
  *total_out = s.sum;
  *ess = s.sum_sq > 0.0 ? s.sum * s.sum / s.sum_sq : 0.0;
  return max_log;
}

// The posterior with the likelihood tempered by the largest exponent that
// keeps min_ess particles (by bisection): *posterior holds prior *
// likelihood^beta / max, *total its sum. Returns beta, and the log of the
// max in *max_log_out (-inf when every particle scores zero: the weights
// are then the prior again). max_ll: the largest log likelihood, which for
// a uniform prior is the untempered posterior's largest log.
template <typename LogPrior>
double temperedPosterior(LogPrior log_prior, const std::vector<double>& ll, double max_ll,
                         double min_ess, std::vector<double>* posterior, double* total_out,
                         double* max_log_out, int threads) {
  double* e = posterior->data();
  const std::size_t n = posterior->size();
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 20; ++k) {
    const double mid = 0.5 * (lo + hi);
    (effectiveSampleSize(log_prior, ll, mid, max_ll, threads) >= min_ess ? lo : hi) = mid;
  }
  const double beta = lo;
  const double max_log = maxBlocks(n, threads, [&](std::size_t i) {
    e[i] = log_prior(i) + beta * ll[i];
    return e[i];
  });
  double total = 0.0;
  if (std::isfinite(max_log)) {
    total = reduceBlockRanges(
        n, threads, 0.0,
        [&](std::size_t begin, std::size_t end, double& sum) {
          addExps(
              begin, end, [&](std::size_t i) { return e[i] - max_log; },
              [&](std::size_t i, double v) {
                e[i] = v;
                sum += v;
              });
        },
        [](double& into, double from) { into += from; });
  }
  *total_out = total;
  *max_log_out = max_log;
  return beta;
}

// applyLikelihood in logarithms, with the prior's (log_prior); *e is
// working storage of N values. Returns beta.
template <typename LogPrior>
double weighInLogarithms(LogPrior log_prior, const std::vector<double>& ll, double min_ess,
                         std::vector<double>* weights, std::vector<double>* e, int threads) {
  double total = 0.0, ess = 0.0;
  double max_log = untemperedPosterior(log_prior, ll, e, &total, &ess, threads);
  double beta = 1.0;
  if (min_ess > 0.0 && ess < min_ess) {
    beta = temperedPosterior(log_prior, ll, max_log, min_ess, e, &total, &max_log, threads);
  }
  // Evidence that rules out every particle alike: the weights stay.
  if (!std::isfinite(max_log)) return beta;
  double* w = weights->data();
  const double* p = e->data();
  forEachParticle(weights->size(), threads, [&](std::size_t i) { w[i] = p[i] / total; });
  return beta;
}

}  // namespace

double applyLikelihood(const std::vector<double>& ll, double min_ess_fraction,
                       std::vector<double>* weights, WeightingScratch* scratch, int threads) {
  std::vector<double>& w = *weights;
  const std::size_t n = w.size();
  // (An unsigned flag and &, not a bool and &&: the loop vectorises.)
  const double first = n > 0 ? w[0] : 0.0;
  const bool uniform =
      reduceBlocks(
          n, threads, 1u, [&](std::size_t i, unsigned& same) { same &= w[i] == first ? 1u : 0u; },
          [](unsigned& into, unsigned from) { into &= from; }) != 0;
  // A share of the effective particles before the scan, not of all of them:
  // recovery's barely weighted guesses count as particles but not as
  // effective ones, and measured against N a cloud salted with them could
  // never keep enough, so every scan was tempered away to nothing.
  const double min_ess = min_ess_fraction * priorEffectiveSampleSize(w, uniform, threads);
  std::vector<double>& e = scratch->log_posterior;
  e.resize(n);
  if (uniform) return weighInLogarithms(ZeroLogPrior(), ll, min_ess, &w, &e, threads);
  if (multiplyDirectly(ll, min_ess, &w, &e, threads)) return 1.0;
  // Otherwise in logarithms.
  logPrior(w, &scratch->log_prior, threads);
  return weighInLogarithms(StoredLogPrior{scratch->log_prior.data()}, ll, min_ess, &w, &e, threads);
}

double meanBeamLikelihood(const std::vector<double>& weights,
                          const std::vector<double>& log_likelihood, double beams, int threads) {
  // The per-beam likelihoods a chunk at a time (addExps), summed as they
  // come: the same sum as writing them all and summing them after.
  return reduceBlockRanges(
      weights.size(), threads, 0.0,
      [&](std::size_t begin, std::size_t end, double& sum) {
        addExps(
            begin, end, [&](std::size_t i) { return log_likelihood[i] / beams; },
            [&](std::size_t i, double per_beam) { sum += weights[i] * per_beam; });
      },
      [](double& into, double from) { into += from; });
}

double temperingEssFraction(LocalizationState fit_state, const Confidence& last,
                            const ParticleFilterParams& params) {
  const bool spread_only = fit_state == LocalizationState::kUncertain && last.rivals == 0 &&
                           last.hit_fraction >= params.confidence.localized_hit_fraction;
  return fit_state == LocalizationState::kLocalized || spread_only
             ? params.tempering_ess_fraction
             : params.tempering_ess_fraction_uncertain;
}

}  // namespace pf

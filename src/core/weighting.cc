#include "pf_localization/core/weighting.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pf_localization/core/fast_math.h"
#include "pf_localization/core/thread_scratch.h"

namespace pf {
namespace {

// ESS of the weights prior * likelihood^beta, from their logarithms.
double effectiveSampleSize(const std::vector<double>& log_prior,
                           const std::vector<double>& log_likelihood, double beta) {
  double max_log = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < log_prior.size(); ++i) {
    max_log = std::max(max_log, log_prior[i] + beta * log_likelihood[i]);
  }
  if (!std::isfinite(max_log)) return 0.0;
  struct WScratch {
    std::vector<double> w;
  };  // kept: no allocation per update
  WScratch& w_scratch = threadScratch<WScratch>();
  std::vector<double>& w = w_scratch.w;
  w.resize(log_prior.size());
  for (std::size_t i = 0; i < log_prior.size(); ++i) {
    w[i] = log_prior[i] + beta * log_likelihood[i] - max_log;
  }
  exps(w.data(), w.size(), w.data());
  double sum = 0.0, sum_sq = 0.0;
  for (double v : w) {
    sum += v;
    sum_sq += v * v;
  }
  return sum * sum / sum_sq;
}

// The prior's effective sample size: after a resampling every weight is the
// same, and it is then N; otherwise it comes from the weights themselves,
// (sum w)^2 / sum w^2, without exponentials.
double priorEffectiveSampleSize(const std::vector<double>& w, bool uniform) {
  double prior_ess = static_cast<double>(w.size());
  if (!uniform) {
    double sum = 0.0, sum_sq = 0.0;
    for (double v : w) {
      sum += v;
      sum_sq += v * v;
    }
    prior_ess = sum_sq > 0.0 ? sum * sum / sum_sq : 0.0;
  }
  return prior_ess;
}

// Nearly always the product prior * likelihood / max likelihood can be
// taken as it is, without a logarithm per particle: when the best product
// is far from underflowing and the scan needs no tempering. Then writes
// the normalised posterior into *weights and returns true; *posterior is
// working storage of N values.
bool multiplyDirectly(const std::vector<double>& ll, double min_ess, std::vector<double>* weights,
                      std::vector<double>* posterior) {
  std::vector<double>& w = *weights;
  std::vector<double>& e = *posterior;
  const std::size_t n = w.size();
  double max_ll = -std::numeric_limits<double>::infinity();
  for (double v : ll) max_ll = std::max(max_ll, v);
  if (!std::isfinite(max_ll)) return false;
  for (std::size_t i = 0; i < n; ++i) e[i] = ll[i] - max_ll;
  exps(e.data(), n, e.data());
  double total = 0.0, total_sq = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    e[i] *= w[i];
    total += e[i];
    total_sq += e[i] * e[i];
    peak = std::max(peak, e[i]);
  }
  if (peak > 1e-100 && !(min_ess > 0.0 && total * total / total_sq < min_ess)) {
    for (std::size_t i = 0; i < n; ++i) w[i] = e[i] / total;
    return true;
  }
  return false;
}

// The prior's logarithms. A constant prior does not change the normalised
// result: zeros spare N logarithms.
void logPrior(const std::vector<double>& w, bool uniform, std::vector<double>* log_prior) {
  const std::size_t n = w.size();
  if (uniform) {
    log_prior->assign(n, 0.0);
  } else {
    log_prior->resize(n);
    for (std::size_t i = 0; i < n; ++i) (*log_prior)[i] = std::log(w[i]);
  }
}

// The untempered posterior, in one pass of exponentials that serves both
// the tempering test and (nearly always) the result: *posterior holds
// prior * likelihood / max, *total its sum. Returns the log of the max, and
// its effective sample size in *ess.
double untemperedPosterior(const std::vector<double>& log_prior, const std::vector<double>& ll,
                           std::vector<double>* posterior, double* total_out, double* ess) {
  std::vector<double>& e = *posterior;
  const std::size_t n = e.size();
  double max_log = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    e[i] = log_prior[i] + ll[i];
    max_log = std::max(max_log, e[i]);
  }
  // When every particle scores zero (possible with z_rand = 0: an end point
  // far from any obstacle has likelihood exp(-800) = 0), max_log is -inf and
  // normalising would give 0/0 = NaN weights, which the resampler collapses
  // onto particle 0. Evidence that rules out all particles alike favours
  // none: the caller leaves the weights as they were.
  double total = 0.0, total_sq = 0.0;
  if (std::isfinite(max_log)) {
    for (std::size_t i = 0; i < n; ++i) e[i] -= max_log;
    exps(e.data(), n, e.data());
    for (std::size_t i = 0; i < n; ++i) {
      total += e[i];
      total_sq += e[i] * e[i];
    }
  }
  *total_out = total;
  *ess = total_sq > 0.0 ? total * total / total_sq : 0.0;
  return max_log;
}

// The posterior with the likelihood tempered by the largest exponent that
// keeps min_ess particles (by bisection): *posterior holds prior *
// likelihood^beta / max, *total its sum. Returns beta, and the log of the
// max in *max_log_out (-inf when every particle scores zero: the weights
// are then the prior again).
double temperedPosterior(const std::vector<double>& log_prior, const std::vector<double>& ll,
                         double min_ess, std::vector<double>* posterior, double* total_out,
                         double* max_log_out) {
  std::vector<double>& e = *posterior;
  const std::size_t n = e.size();
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 20; ++k) {
    const double mid = 0.5 * (lo + hi);
    (effectiveSampleSize(log_prior, ll, mid) >= min_ess ? lo : hi) = mid;
  }
  const double beta = lo;
  double max_log = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    e[i] = log_prior[i] + beta * ll[i];
    max_log = std::max(max_log, e[i]);
  }
  double total = 0.0;
  if (std::isfinite(max_log)) {
    for (std::size_t i = 0; i < n; ++i) e[i] -= max_log;
    exps(e.data(), n, e.data());
    for (std::size_t i = 0; i < n; ++i) total += e[i];
  }
  *total_out = total;
  *max_log_out = max_log;
  return beta;
}

}  // namespace

double applyLikelihood(const std::vector<double>& ll, double min_ess_fraction,
                       std::vector<double>* weights, WeightingScratch* scratch) {
  std::vector<double>& w = *weights;
  const std::size_t n = w.size();
  const bool uniform = std::all_of(w.begin(), w.end(), [&](double v) { return v == w.front(); });
  // A share of the effective particles before the scan, not of all of them:
  // recovery's barely weighted guesses count as particles but not as
  // effective ones, and measured against N a cloud salted with them could
  // never keep enough, so every scan was tempered away to nothing.
  const double min_ess = min_ess_fraction * priorEffectiveSampleSize(w, uniform);
  std::vector<double>& e = scratch->log_posterior;
  e.resize(n);
  if (!uniform && multiplyDirectly(ll, min_ess, &w, &e)) return 1.0;
  // Otherwise in logarithms.
  std::vector<double>& log_prior = scratch->log_prior;
  logPrior(w, uniform, &log_prior);
  double total = 0.0, ess = 0.0;
  double max_log = untemperedPosterior(log_prior, ll, &e, &total, &ess);
  double beta = 1.0;
  if (min_ess > 0.0 && ess < min_ess) {
    beta = temperedPosterior(log_prior, ll, min_ess, &e, &total, &max_log);
  }
  // Evidence that rules out every particle alike: the weights stay.
  if (!std::isfinite(max_log)) return beta;
  for (std::size_t i = 0; i < n; ++i) w[i] = e[i] / total;
  return beta;
}

double meanBeamLikelihood(const std::vector<double>& weights,
                          const std::vector<double>& log_likelihood, double beams) {
  struct PerBeamScratch {
    std::vector<double> per_beam;
  };  // kept: no allocation per update
  PerBeamScratch& per_beam_scratch = threadScratch<PerBeamScratch>();
  std::vector<double>& per_beam = per_beam_scratch.per_beam;
  const std::size_t n = weights.size();
  per_beam.resize(n);
  for (std::size_t i = 0; i < n; ++i) per_beam[i] = log_likelihood[i] / beams;
  exps(per_beam.data(), n, per_beam.data());
  double mean_beam = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean_beam += weights[i] * per_beam[i];
  return mean_beam;
}

}  // namespace pf

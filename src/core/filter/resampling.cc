#include "pf_localization/core/filter/resampling.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/util/bin_table.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {

const ParameterTable<KldParams>& kldParameters() {
  using P = KldParams;
  using I = ParamInfo;
  static const ParameterTable<P> table = {
      member(&P::min_particles,
             I("min_particles", "particles", "KLD-sampling never goes below this")
                 .in(Range::atLeast(1))
                 .amcl()
                 .live(0, 1000000)),
      member(&P::max_particles, I("max_particles", "particles",
                                  "and never above this; global localization starts with this many")
                                    .in(Range::atLeast(1))
                                    .amcl()
                                    .live(0, 1000000)),
      member(&P::kld_err, I("kld_err", "", "KLD-sampling bound on the approximation error")
                              .in(Range::above(0))
                              .amcl()
                              .live(0, 1)),
      // amcl's kld_z is the normal quantile of this probability (readConfig converts it).
      member(&P::confidence, I("kld_confidence", "", "probability that the KLD bound holds")
                                 .in(Range::open(0, 1))
                                 .amclAlias("kld_z")
                                 .live(0, 1)),
  };
  return table;
}

double effectiveSampleSize(const std::vector<double>& weights, int threads) {
  const double sum_sq =
      sumBlocks(weights.size(), threads, [&](std::size_t i) { return weights[i] * weights[i]; });
  return sum_sq > 0.0 ? 1.0 / sum_sq : 0.0;
}

namespace {

// systematicResample on several threads: the running sums of the weights
// first, one after the other (the same additions as the one-thread loop, so
// the same values), then each thread's slice of the survivors finds its
// first particle by bisection in them and goes on as the loop does.
void systematicResampleSliced(const ParticleSet& in, std::size_t n, Random* random,
                              ParticleSet* out, int threads) {
  struct Cumulative {
    std::vector<double> sums;
  };  // kept: no allocation per update
  std::vector<double>& cumulative = threadScratch<Cumulative>().sums;
  const std::size_t m = in.size();
  // Only grows: the first m are written below, and a resize up after a
  // smaller cloud would zero-fill them first (8 MB at a million).
  if (cumulative.size() < m) cumulative.resize(m);
  double running = 0.0;
  for (std::size_t j = 0; j < m; ++j) cumulative[j] = running += in.weight[j];
  const double step = cumulative[m - 1] / static_cast<double>(n);
  const double offset = random->uniform();
  const double* c = cumulative.data();
  forEachSlice(n, threads, [&](std::size_t begin, std::size_t end) {
    const double first = (offset + static_cast<double>(begin)) * step;
    std::size_t j = std::min<std::size_t>(std::upper_bound(c, c + m, first) - c, m - 1);
    for (std::size_t i = begin; i < end; ++i) {
      const double pointer = (offset + static_cast<double>(i)) * step;
      while (pointer >= c[j] && j + 1 < m) ++j;
      out->x[i] = in.x[j];
      out->y[i] = in.y[j];
      out->yaw[i] = in.yaw[j];
    }
  });
}

}  // namespace

void systematicResample(const ParticleSet& in, std::size_t n, Random* random, ParticleSet* out,
                        int threads) {
  out->resize(in.empty() ? 0 : n);
  if (out->empty()) return;
  if (threadsFor(n, threads) > 1) {
    systematicResampleSliced(in, n, random, out, threads);
    out->setUniformWeights();
    return;
  }
  double total = 0.0;
  for (double w : in.weight) total += w;
  const double step = total / static_cast<double>(n);
  const double offset = random->uniform();
  double cumulative = in.weight[0];
  std::size_t j = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // (offset + i) * step rather than a running sum, so that the pointers
    // cannot drift over a million particles.
    const double pointer = (offset + static_cast<double>(i)) * step;
    // The last particle absorbs rounding in the cumulative sum.
    while (pointer >= cumulative && j + 1 < in.size()) cumulative += in.weight[++j];
    out->x[i] = in.x[j];
    out->y[i] = in.y[j];
    out->yaw[i] = in.yaw[j];
  }
  out->setUniformWeights();
}

void systematicResample(ParticleSet* particles, std::size_t n, Random* random) {
  ParticleSet out;
  systematicResample(*particles, n, random, &out);
  *particles = std::move(out);
}

double normalQuantile(double p) {
  if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("normalQuantile: p must be in (0, 1)");
  // Acklam's rational approximation of the inverse normal CDF (relative error
  // below 1.2e-9), refined by one Halley step against std::erfc.
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double p_low = 0.02425;
  double x;
  if (p < p_low) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else if (p <= 1.0 - p_low) {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  } else {
    const double q = std::sqrt(-2.0 * std::log(1.0 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(x * x / 2.0);
  return x - u / (1.0 + x * u / 2.0);
}

double kldBound(std::size_t k, double kld_err, double confidence) {
  if (k <= 1) return 1.0;
  const double z = normalQuantile(confidence);
  const double a = 2.0 / (9.0 * static_cast<double>(k - 1));
  const double b = 1.0 - a + std::sqrt(a) * z;
  return static_cast<double>(k - 1) / (2.0 * kld_err) * b * b * b;
}

namespace {

// The occupied bins of some particles and the weight in each, in order of
// first appearance. Kept between calls, so that binning allocates nothing.
struct KldBins {
  BinTable bins;
  std::vector<uint64_t> keys;
  std::vector<double> weight;
};

// Bins the particles [begin, end) into *out.
void binWeights(const ParticleSet& particles, std::size_t begin, std::size_t end,
                const KldParams& params, KldBins* out) {
  out->bins.reset(end - begin);
  out->keys.clear();
  out->weight.clear();
  // Resampling leaves the copies of one particle side by side, so the bin of
  // the particle before is the likeliest: it spares most hash look-ups.
  uint64_t last_key = ~uint64_t{0};
  int id = -1;
  for (std::size_t i = begin; i < end; ++i) {
    const uint64_t key = BinTable::key(binIndex(particles.x[i], params.bin_xy),
                                       binIndex(particles.y[i], params.bin_xy),
                                       binIndex(particles.yaw[i], params.bin_yaw));
    if (key != last_key) {
      id = out->bins.insert(key);
      last_key = key;
      if (static_cast<std::size_t>(id) == out->weight.size()) {
        out->weight.push_back(0.0);
        out->keys.push_back(key);
      }
    }
    out->weight[id] += particles.weight[i];
  }
}

// The bins of the whole cloud: one block's as they are; several blocks'
// binned each on its own, then merged in block order (each bin's weight is
// the sum of its blocks' in that order).
const KldBins& binWeights(const ParticleSet& particles, const KldParams& params, int threads) {
  struct Scratch {
    KldBins whole;
    std::vector<KldBins> blocks;
  };
  Scratch& scratch = threadScratch<Scratch>();
  const std::size_t n = particles.size();
  const std::size_t blocks = blockCount(n);
  if (blocks <= 1) {
    binWeights(particles, 0, n, params, &scratch.whole);
    return scratch.whole;
  }
  if (scratch.blocks.size() < blocks) scratch.blocks.resize(blocks);
  KldBins* parts = scratch.blocks.data();
  forEachBlock(n, threads, [&](std::size_t b, std::size_t begin, std::size_t end) {
    binWeights(particles, begin, end, params, &parts[b]);
  });
  KldBins& whole = scratch.whole;
  std::size_t most = 0;  // bins, at most
  for (std::size_t b = 0; b < blocks; ++b) most += parts[b].keys.size();
  whole.bins.reset(most);
  whole.keys.clear();
  whole.weight.clear();
  for (std::size_t b = 0; b < blocks; ++b) {
    for (std::size_t k = 0; k < parts[b].keys.size(); ++k) {
      const int id = whole.bins.insert(parts[b].keys[k]);
      if (static_cast<std::size_t>(id) == whole.weight.size()) {
        whole.weight.push_back(parts[b].weight[k]);
        whole.keys.push_back(parts[b].keys[k]);
      } else {
        whole.weight[id] += parts[b].weight[k];
      }
    }
  }
  return whole;
}

}  // namespace

std::size_t occupiedBins(const ParticleSet& particles, const KldParams& params, int threads) {
  // A bin counts when its weight promises at least one survivor out of a
  // resample of the current size: bins holding only negligible particles
  // will be empty after resampling and must not inflate k.
  const double threshold = particles.empty() ? 0.0 : 1.0 / static_cast<double>(particles.size());
  const std::vector<double>& bin_weight = binWeights(particles, params, threads).weight;
  std::size_t k = 0;
  for (double w : bin_weight) k += w >= threshold ? 1 : 0;
  return k;
}

std::size_t kldParticleCount(const ParticleSet& particles, const KldParams& params, int threads) {
  // A fixed budget (min_particles = max_particles, as amcl is often run) is
  // the answer whatever the bins say: no need to bin 5000 particles for it.
  if (params.min_particles == params.max_particles) {
    return static_cast<std::size_t>(std::max(params.max_particles, 0));
  }
  const std::size_t k = occupiedBins(particles, params, threads);
  const double n = std::ceil(kldBound(k, params.kld_err, params.confidence));
  const double lo = params.min_particles, hi = params.max_particles;
  return static_cast<std::size_t>(std::clamp(n, lo, hi));
}

}  // namespace pf

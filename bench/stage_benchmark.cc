// One benchmark case per stage of the filter update, ns per particle, on a
// tracking cloud of the synthetic world (bench_world.h).
#include <benchmark/benchmark.h>

#include <cstddef>
#include <vector>

#include "bench_world.h"
#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/core/filter/weighting.h"
#include "pf_localization/core/motion/odometry_motion_model.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"

namespace {

using pf_bench::castScan;
using pf_bench::pillarMap;

// A tracking cloud of 5000 particles around (9, 9, 0.3), weighted by a scan
// ray cast from there, as the filter holds it between its stages.
struct StageWorld {
  pf::OccupancyGrid grid = pillarMap(400);
  pf::LikelihoodFieldModel model{grid, beamParams()};
  pf::ParticleSet particles;
  pf::PreparedScan scan;
  std::vector<double> log_likelihood;

  static pf::LikelihoodFieldModelParams beamParams() {
    pf::LikelihoodFieldModelParams p;
    p.max_beams = 60;
    return p;
  }
  explicit StageWorld(std::size_t n) {
    pf::Random random(3);
    particles.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      particles.setPose(
          i, {9.0 + random.gaussian(0.1), 9.0 + random.gaussian(0.1), 0.3 + random.gaussian(0.05)});
    }
    particles.setUniformWeights();
    scan = model.prepare(castScan(grid, {9.0, 9.0, 0.3}, 360));
    model.logLikelihoods(scan, particles, &log_likelihood);
    pf::WeightingScratch scratch;
    pf::applyLikelihood(log_likelihood, 0.0, &particles.weight, &scratch);
  }
};

void perParticle(benchmark::State& state, std::size_t n) {
  state.counters["ns_per_particle"] =
      benchmark::Counter(static_cast<double>(n) * state.iterations(),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

constexpr int kStageParticles = 5000;

void BM_StageMotion(benchmark::State& state) {
  StageWorld world(state.range(0));
  pf::OdometryMotionParams params;
  params.fault_fraction = 0.01;  // as the filter runs by default
  const pf::OdometryMotionModel model(params);
  pf::Random random(4);
  std::vector<uint8_t> faulty;
  pf::ParticleSet& p = world.particles;
  double x = 0.0;
  for (auto _ : state) {
    model.apply({x, 0.0, 0.0}, {x + 0.03, 0.002, 0.01}, 0.01, &p, &random, &faulty);
    x += 0.03;
    benchmark::DoNotOptimize(p.x.data());
  }
  perParticle(state, p.size());
}
BENCHMARK(BM_StageMotion)->Arg(kStageParticles);

void BM_StageSensor(benchmark::State& state) {
  StageWorld world(state.range(0));
  for (auto _ : state) {
    world.model.logLikelihoods(world.scan, world.particles, &world.log_likelihood);
    benchmark::DoNotOptimize(world.log_likelihood.data());
  }
  perParticle(state, world.particles.size());
}
BENCHMARK(BM_StageSensor)->Arg(kStageParticles);

// Weighting from a uniform prior (after a resampling) or a weighted one
// (no resampling last time: most updates on a recording); tempering off,
// as when tracking.
void BM_StageWeighting(benchmark::State& state) {
  StageWorld world(state.range(0));
  const bool uniform = state.range(1) == 0;
  if (uniform) world.particles.setUniformWeights();
  const std::vector<double> prior = world.particles.weight;
  std::vector<double> weights = prior;
  pf::WeightingScratch scratch;
  for (auto _ : state) {
    std::copy(prior.begin(), prior.end(), weights.begin());
    benchmark::DoNotOptimize(pf::applyLikelihood(world.log_likelihood, 0.02, &weights, &scratch));
    benchmark::DoNotOptimize(pf::meanBeamLikelihood(weights, world.log_likelihood, 60.0));
    benchmark::DoNotOptimize(pf::effectiveSampleSize(weights));
  }
  perParticle(state, weights.size());
}
BENCHMARK(BM_StageWeighting)
    ->ArgNames({"particles", "weighted_prior"})
    ->Args({kStageParticles, 0})
    ->Args({kStageParticles, 1});

void BM_StageResample(benchmark::State& state) {
  StageWorld world(state.range(0));
  pf::Random random(5);
  pf::ParticleSet out;
  for (auto _ : state) {
    pf::systematicResample(world.particles, world.particles.size(), &random, &out);
    benchmark::DoNotOptimize(out.x.data());
  }
  perParticle(state, world.particles.size());
}
BENCHMARK(BM_StageResample)->Arg(kStageParticles);

void BM_StageKldBinning(benchmark::State& state) {
  StageWorld world(state.range(0));
  const pf::KldParams params;
  for (auto _ : state) benchmark::DoNotOptimize(pf::kldParticleCount(world.particles, params));
  perParticle(state, world.particles.size());
}
BENCHMARK(BM_StageKldBinning)->Arg(kStageParticles);

void BM_StageEstimate(benchmark::State& state) {
  StageWorld world(state.range(0));
  const pf::ClusterParams params;
  for (auto _ : state) {
    const pf::PoseEstimate e = pf::estimatePose(world.particles, params);
    benchmark::DoNotOptimize(e.pose);
  }
  perParticle(state, world.particles.size());
}
BENCHMARK(BM_StageEstimate)->Arg(kStageParticles);

// The verdict: the beams that fit at the estimate, and the clusters' spread.
void BM_StageConfidence(benchmark::State& state) {
  StageWorld world(state.range(0));
  const pf::PoseEstimate e = pf::estimatePose(world.particles, pf::ClusterParams());
  const pf::ConfidenceParams params;
  for (auto _ : state) {
    const double hits = world.model.hitFraction(world.scan, e.pose, params.hit_distance);
    const pf::Confidence c = pf::assessConfidence(world.particles, e, hits, params);
    benchmark::DoNotOptimize(c.state);
  }
  perParticle(state, world.particles.size());
}
BENCHMARK(BM_StageConfidence)->Arg(kStageParticles);

}  // namespace

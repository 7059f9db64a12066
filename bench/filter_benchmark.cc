// Benchmarks of the filter's hot paths (Google Benchmark).
//
// Build with -DPF_BUILD_BENCHMARKS=ON and run scripts/benchmark.sh. The world
// is synthetic and fixed: a square-room map with a grid of pillars, scans with
// every beam valid, particles scattered around one pose, so the figures only
// depend on the code and the machine.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "pf_localization/core/beam_model.h"
#include "pf_localization/core/likelihood_field_model.h"
#include "pf_localization/core/particle_filter.h"
#include "pf_localization/core/resampler.h"
#include "pf_localization/core/scan_refiner.h"

namespace {

// A side x side map at 0.05 m with walls on the border and a pillar every 2 m.
pf::OccupancyGrid pillarMap(int side) {
  std::vector<int8_t> data(static_cast<std::size_t>(side) * side, 0);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      const bool wall = x == 0 || y == 0 || x == side - 1 || y == side - 1;
      const bool pillar = x % 40 < 4 && y % 40 < 4;
      if (wall || pillar) data[static_cast<std::size_t>(y) * side + x] = 100;
    }
  }
  return pf::OccupancyGrid(side, side, 0.05, {0.0, 0.0, 0.0}, std::move(data));
}

pf::LaserScan fullScan(int beams) {
  pf::LaserScan scan;
  scan.angle_min = -M_PI;
  scan.angle_increment = 2.0 * M_PI / beams;
  scan.range_min = 0.02;
  scan.range_max = 5.0;
  for (int i = 0; i < beams; ++i) scan.ranges.push_back(1.0f + 3.0f * (i % 7) / 7.0f);
  return scan;
}

pf::ParticleSet scatter(std::size_t n, pf::Random* random) {
  pf::ParticleSet set;
  set.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    set.setPose(i, {10.0 + random->gaussian(1.0), 10.0 + random->gaussian(1.0),
                    random->uniform(-M_PI, M_PI)});
  }
  set.setUniformWeights();
  return set;
}

void BM_SensorUpdate(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(1));
  pf::LikelihoodFieldModelParams params;
  params.max_beams = beams;
  params.threads = static_cast<int>(state.range(2));
  const pf::LikelihoodFieldModel model(pillarMap(400), params);
  pf::Random random(1);
  const pf::ParticleSet particles = scatter(state.range(0), &random);
  const pf::PreparedScan scan = model.prepare(fullScan(beams));
  std::vector<double> out;
  for (auto _ : state) {
    model.logLikelihoods(scan, particles, &out);
    benchmark::DoNotOptimize(out.data());
  }
  const double pairs = static_cast<double>(state.range(0)) * beams;
  state.counters["ns_per_particle_beam"] = benchmark::Counter(
      pairs * state.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SensorUpdate)
    ->Args({10000, 60, 1})
    ->Args({100000, 60, 1})
    ->Args({100000, 360, 1})
    ->Args({100000, 60, 2})
    ->UseRealTime();

void BM_FullUpdate(benchmark::State& state) {
  const std::size_t n = state.range(0);
  pf::ParticleFilterParams params;
  params.kld.min_particles = params.kld.max_particles = static_cast<int>(n);
  params.sensor.max_beams = static_cast<int>(state.range(1));
  params.update_min_d = params.update_min_a = 0.0;
  pf::ParticleFilter filter(params);
  filter.setMap(pillarMap(400));
  filter.initializeGaussian({10.0, 10.0, 0.0}, Eigen::Vector3d(1.0, 1.0, 0.5).asDiagonal());
  const pf::LaserScan scan = fullScan(360);
  double x = 0.0;
  filter.update({x, 0.0, 0.0}, scan);
  for (auto _ : state) {
    x += 0.05;
    benchmark::DoNotOptimize(filter.update({x, 0.0, 0.0}, scan));
  }
  state.counters["particles"] = static_cast<double>(filter.particles().size());
}
BENCHMARK(BM_FullUpdate)
    ->ArgsProduct({{1000, 10000, 100000, 1000000}, {60, 360}})
    ->Unit(benchmark::kMillisecond);

// A scan of `beams` beams over a full turn, ray cast on `grid` from `pose`
// in steps of 5 mm: every end point lies on a wall or a pillar.
pf::LaserScan castScan(const pf::OccupancyGrid& grid, const pf::Pose2& pose, int beams) {
  pf::LaserScan scan = fullScan(beams);
  scan.range_max = 20.0;  // so that every beam finds a pillar or the outer wall
  for (int i = 0; i < beams; ++i) {
    const double a = pose.yaw + scan.angle_min + i * scan.angle_increment;
    scan.ranges[i] = 0.0f;  // no return
    for (double r = 0.05; r < scan.range_max; r += 0.005) {
      const pf::CellIndex c = grid.worldToCell(pose.x + r * std::cos(a), pose.y + r * std::sin(a));
      if (grid.state(c) == pf::CellState::kOccupied) {
        scan.ranges[i] = static_cast<float>(r);
        break;
      }
    }
  }
  return scan;
}

// One scan fitted to the map from a start 6 cm and 1.1 deg off, as
// ParticleFilter does after each update (and for each scan between updates).
void BM_ScanRefinement(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(0));
  const pf::OccupancyGrid grid = pillarMap(400);
  pf::LikelihoodFieldModelParams params;
  params.max_beams = beams;
  const pf::LikelihoodFieldModel model(grid, params);
  const pf::ScanRefiner refiner(model.field(), pf::ScanRefinerParams());
  const pf::Pose2 truth{9.0, 9.0, 0.3};
  const pf::PreparedScan scan = model.prepare(castScan(grid, truth, beams));
  const pf::Pose2 start{truth.x + 0.05, truth.y - 0.03, truth.yaw + 0.02};
  const Eigen::Matrix3d cloud = Eigen::Vector3d(0.01, 0.01, 0.003).asDiagonal();
  int iterations = 0;
  for (auto _ : state) {
    const pf::ScanRefinement r = refiner.refine(scan, start, cloud);
    if (!r.accepted) state.SkipWithError(r.rejection.c_str());
    iterations = r.iterations;
    benchmark::DoNotOptimize(r.pose);
  }
  state.counters["beams"] = static_cast<double>(scan.size());
  state.counters["gauss_newton_iterations"] = iterations;
}
BENCHMARK(BM_ScanRefinement)->Arg(60)->Arg(360)->Unit(benchmark::kMicrosecond);

// The sensor models side by side (0: likelihood field, 1: the same with
// beam skipping, 2: beam model) on a scan ray cast from the cloud's centre,
// so that the beam model's expected ranges are the measured ones there.
void BM_SensorModel(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(2));
  const pf::OccupancyGrid grid = pillarMap(400);
  pf::ParticleFilterParams params;
  params.sensor.max_beams = beams;
  params.laser_model_type =
      state.range(0) == 2 ? pf::LaserModelType::kBeam : pf::LaserModelType::kLikelihoodFieldProb;
  params.sensor.beam_skip = state.range(0) == 1;
  const std::unique_ptr<pf::SensorModel> model = pf::makeSensorModel(grid, params);
  pf::Random random(1);
  const pf::ParticleSet particles = scatter(state.range(1), &random);
  const pf::PreparedScan scan = model->prepare(castScan(grid, {10.0, 10.0, 0.0}, beams));
  std::vector<double> out;
  for (auto _ : state) {
    model->logLikelihoods(scan, particles, &out);
    benchmark::DoNotOptimize(out.data());
  }
  const double pairs = static_cast<double>(state.range(1)) * static_cast<double>(scan.size());
  state.counters["ns_per_particle_beam"] = benchmark::Counter(
      pairs * state.iterations(), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SensorModel)
    ->ArgNames({"model", "particles", "beams"})
    ->Args({0, 10000, 60})
    ->Args({1, 10000, 60})
    ->Args({2, 10000, 60})
    ->Args({2, 1000, 360})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// Building the beam model's ray-casting table (the exact distance transform,
// uncapped) for a side x side map, once per map.
void BM_RayCasterTable(benchmark::State& state) {
  const pf::OccupancyGrid grid = pillarMap(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const pf::DistanceFieldRayCaster caster(grid);
    benchmark::DoNotOptimize(&caster);
  }
}
BENCHMARK(BM_RayCasterTable)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

void BM_SystematicResample(benchmark::State& state) {
  pf::Random random(2);
  const pf::ParticleSet base = scatter(state.range(0), &random);
  for (auto _ : state) {
    state.PauseTiming();
    pf::ParticleSet set = base;
    state.ResumeTiming();
    pf::systematicResample(&set, set.size(), &random);
    benchmark::DoNotOptimize(set.x.data());
  }
}
BENCHMARK(BM_SystematicResample)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);

void BM_LikelihoodField(benchmark::State& state) {
  const pf::OccupancyGrid grid = pillarMap(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    const pf::LikelihoodField field(grid, 2.0);
    benchmark::DoNotOptimize(field.distances().data());
  }
}
BENCHMARK(BM_LikelihoodField)->Arg(1000)->Arg(2000)->Arg(4000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

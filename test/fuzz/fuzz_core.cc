// libFuzzer target: arbitrary bytes -> filter parameters, a map, an
// initialisation and a sequence of odometry poses and scans, fed through the
// core's public entry points. Built only with -DPF_BUILD_FUZZERS=ON and clang
// (see scripts/fuzz.sh); the input format is described in fuzz_input.h and
// below, and test/fuzz/make_corpus.py writes valid seeds.
//
// Findings are crashes: a sanitizer report (ASan, UBSan with
// -fno-sanitize-recover), an exception the core does not document, or a
// broken invariant (PF_FUZZ_CHECK): the particle count outside
// [min_particles, max_particles], weights that are not finite or do not sum
// to 1, more beams than asked for, a bad-input rejection without a message.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz_input.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"

namespace {

using pf_fuzz::Input;

// PF_FUZZ_VERBOSE=1: print what the input decodes to, to read a reproducer.
bool verbose() {
  static const bool v = std::getenv("PF_FUZZ_VERBOSE") != nullptr;
  return v;
}
#define PF_FUZZ_LOG(...)                   \
  do {                                     \
    if (verbose()) {                       \
      std::fprintf(stderr, "fuzz_core: "); \
      std::fprintf(stderr, __VA_ARGS__);   \
      std::fprintf(stderr, "\n");          \
    }                                      \
  } while (0)

void logParams(const pf::ParticleFilterParams& p) {
  PF_FUZZ_LOG(
      "params: %s particles %d..%d kld_err %g conf %g bins %g %g update_min %g %g ess %g "
      "seed %llu alphas %g %g %g %g %g z_hit %g z_rand %g sigma %g max_dist %g beams %d "
      "range %g..%g clusters %g %g recovery %g %g",
      p.motion.kind == pf::OdometryMotionParams::Kind::kOmni ? "omni" : "diff", p.kld.min_particles,
      p.kld.max_particles, p.kld.kld_err, p.kld.confidence, p.kld.bin_xy, p.kld.bin_yaw,
      p.update_min_d, p.update_min_a, p.resample_ess_fraction,
      static_cast<unsigned long long>(p.seed), p.motion.alpha1, p.motion.alpha2, p.motion.alpha3,
      p.motion.alpha4, p.motion.alpha5, p.sensor.z_hit, p.sensor.z_rand, p.sensor.sigma_hit,
      p.sensor.max_distance, p.sensor.max_beams, p.sensor.range_min, p.sensor.range_max,
      p.clusters.cell_xy, p.clusters.cell_yaw, p.recovery.alpha_slow, p.recovery.alpha_fast);
}

void logScan(const pf::LaserScan& s) {
  if (!verbose()) return;
  std::string r;
  for (float v : s.ranges) r += " " + std::to_string(v);
  PF_FUZZ_LOG("scan: angle_min %g inc %g range %g..%g sensor (%g, %g, %g), %zu ranges:%s",
              s.angle_min, s.angle_increment, s.range_min, s.range_max, s.sensor_pose.x,
              s.sensor_pose.y, s.sensor_pose.yaw, s.ranges.size(), r.c_str());
}

// Input layout, in order:
//   params:  flags u8 (bit0 omni, bit1 max < min allowed, bit2 laser_max_range
//            given, bit3 laser_min_range given, bit4 recovery on, bit5
//            refine_estimate on),
//            min_particles u8, max_particles u8, kld_err, kld_confidence,
//            kld_bin_xy, kld_bin_yaw, update_min_d, update_min_a,
//            resample_ess_fraction, seed u8, alpha1..5, z_hit, z_rand,
//            sigma_hit, max_distance, max_beams u8, [range_min], [range_max],
//            cluster_xy, cluster_yaw, [alpha_slow, alpha_fast]
//   map:     mflags u8 (bits0-2 size fault, bits3-4 cell style), width u8,
//            height u8, [fault byte], resolution, origin x, y, yaw, cells
//   init:    kind u8, then the mean and covariance for a Gaussian
//   steps:   count u8, then per step an op u8 and its operands
pf::ParticleFilterParams readParams(Input& in) {
  pf::ParticleFilterParams p;
  const uint8_t flags = in.u8();
  p.motion.kind = (flags & 1) ? pf::OdometryMotionParams::Kind::kOmni
                              : pf::OdometryMotionParams::Kind::kDifferential;
  const int raw_min = in.u8();
  // Mostly 1..100, sometimes -2..1 to exercise the validation.
  p.kld.min_particles = raw_min < 4 ? raw_min - 2 : raw_min % 100 + 1;
  p.kld.max_particles = p.kld.min_particles + in.u8() % 101 - ((flags & 2) ? 3 : 0);
  p.kld.kld_err = in.num(0.001, 0.5);
  p.kld.confidence = in.num(0.0, 1.0);
  p.kld.bin_xy = in.num(0.01, 2.0);
  p.kld.bin_yaw = in.num(0.01, 1.0);
  p.update_min_d = in.num(0.0, 0.5);
  p.update_min_a = in.num(0.0, 1.0);
  p.resample_ess_fraction = in.num(0.0, 1.0);
  p.seed = in.u8();
  p.motion.alpha1 = in.num(0.0, 0.5);
  p.motion.alpha2 = in.num(0.0, 0.5);
  p.motion.alpha3 = in.num(0.0, 0.5);
  p.motion.alpha4 = in.num(0.0, 0.5);
  p.motion.alpha5 = in.num(0.0, 0.5);
  p.sensor.z_hit = in.num(0.0, 1.0);
  p.sensor.z_rand = in.num(0.0, 1.0);
  p.sensor.sigma_hit = in.num(0.01, 1.0);
  p.sensor.max_distance = in.num(0.05, 3.0);
  p.sensor.max_beams = static_cast<int>(in.u8()) - 2;
  if (flags & 8) p.sensor.range_min = in.num(0.0, 1.0);
  if (flags & 4) p.sensor.range_max = in.num(0.0, 20.0);
  p.clusters.cell_xy = in.num(0.05, 2.0);
  p.clusters.cell_yaw = in.num(0.05, 1.5);
  if (flags & 16) {
    p.recovery.alpha_slow = in.num(0.0, 0.1);
    p.recovery.alpha_fast = in.num(0.0, 1.0);
  }
  p.refine_estimate = (flags & 32) != 0;
  return p;
}

// nullptr when the bytes describe a grid the constructor rejects (it must say why).
std::unique_ptr<pf::OccupancyGrid> readMap(Input& in) {
  const uint8_t mflags = in.u8();
  int w = 1 + in.u8() % 40;
  int h = 1 + in.u8() % 40;
  const int fault = mflags & 7;
  if (fault == 0) w = static_cast<int8_t>(in.u8());  // zero and negative too
  if (fault == 1) h = static_cast<int8_t>(in.u8());
  const double res = in.num(0.01, 0.5);
  const pf::Pose2 origin{in.num(-20.0, 20.0), in.num(-20.0, 20.0), in.num(-4.0, 4.0)};
  std::size_t n = w > 0 && h > 0 ? static_cast<std::size_t>(w) * h : 0;
  if (fault == 2) n = n + in.u8() % 3 - 1;  // one too few, right, one too many
  std::vector<int8_t> cells(n, 0);
  const int style = (mflags >> 3) & 3;
  for (std::size_t i = 0; i < n; ++i) {
    const int x = w > 0 ? static_cast<int>(i % w) : 0;
    const int y = w > 0 ? static_cast<int>(i / w) : 0;
    switch (style) {
      case 0: {  // free, walls, unknown and odd values from the bytes
        const uint8_t b = in.u8();
        cells[i] = b < 120 ? 0 : b < 200 ? 100 : b < 230 ? -1 : static_cast<int8_t>(b);
        break;
      }
      case 1:  // a walled room, free inside
        cells[i] = (x == 0 || y == 0 || x == w - 1 || y == h - 1) ? 100 : 0;
        break;
      case 2:  // every cell free
        cells[i] = 0;
        break;
      default:  // raw values, anything goes
        cells[i] = static_cast<int8_t>(in.u8());
        break;
    }
  }
  PF_FUZZ_LOG("map: %d x %d (%zu cells, style %d) resolution %g origin (%g, %g, %g)", w, h, n,
              style, res, origin.x, origin.y, origin.yaw);
  try {
    return std::make_unique<pf::OccupancyGrid>(w, h, res, origin, std::move(cells));
  } catch (const std::invalid_argument& e) {
    PF_FUZZ_CHECK(std::strstr(e.what(), "OccupancyGrid") != nullptr, "unclear message: %s",
                  e.what());
    return nullptr;
  }
}

pf::Pose2 readPose(Input& in, double xy, double yaw) {
  return {in.num(-xy, xy), in.num(-xy, xy), in.num(-yaw, yaw)};
}

pf::LaserScan readScan(Input& in) {
  pf::LaserScan scan;
  const int n = in.u8() % 96;  // 0 too
  scan.angle_min = in.num(-4.0, 4.0);
  scan.angle_increment = in.num(-0.2, 0.2);
  scan.range_min = in.num(0.0, 1.0);
  scan.range_max = in.num(0.0, 30.0);
  scan.sensor_pose = readPose(in, 0.5, 4.0);
  scan.ranges.resize(n);
  for (float& r : scan.ranges) r = static_cast<float>(in.num(0.0, 12.0));
  return scan;
}

// Spoils one field of a scan with a special value.
void spoilScan(Input& in, pf::LaserScan* scan) {
  const double v = in.num(-1.0, 1.0);
  switch (in.u8() % 8) {
    case 0:
      scan->angle_min = v;
      break;
    case 1:
      scan->angle_increment = v;
      break;
    case 2:
      scan->range_min = v;
      break;
    case 3:
      scan->range_max = v;
      break;
    case 4:
      scan->sensor_pose.x = v;
      break;
    case 5:
      scan->sensor_pose.yaw = v;
      break;
    case 6:
      if (!scan->ranges.empty())
        scan->ranges[in.u8() % scan->ranges.size()] = static_cast<float>(v);
      break;
    default:
      scan->ranges.clear();
      break;
  }
}

void checkBeams(const pf::LaserScan& scan, const pf::ParticleFilterParams& p) {
  std::size_t valid = 0;
  const std::vector<pf::Beam> beams =
      pf::selectBeams(scan, p.sensor.max_beams, p.sensor.range_min, p.sensor.range_max, &valid);
  PF_FUZZ_CHECK(valid <= scan.ranges.size(), "%zu valid of %zu", valid, scan.ranges.size());
  PF_FUZZ_CHECK(beams.size() <= valid, "%zu beams from %zu valid", beams.size(), valid);
  PF_FUZZ_CHECK(
      p.sensor.max_beams <= 0 || beams.size() <= static_cast<std::size_t>(p.sensor.max_beams),
      "%zu beams for max_beams %d", beams.size(), p.sensor.max_beams);
  for (const pf::Beam& b : beams) {
    PF_FUZZ_CHECK(std::isfinite(b.range) && b.range > 0.0f, "beam range %g", b.range);
  }
  // Unlimited beams as well.
  const std::vector<pf::Beam> all = pf::selectBeams(scan, 0);
  PF_FUZZ_CHECK(all.size() <= scan.ranges.size(), "%zu of %zu", all.size(), scan.ranges.size());
}

void checkFilter(const pf::ParticleFilter& filter, const pf::UpdateReport& report) {
  const pf::ParticleFilterParams& p = filter.params();
  const pf::ParticleSet& s = filter.particles();
  PF_FUZZ_CHECK(
      s.x.size() == s.y.size() && s.x.size() == s.yaw.size() && s.x.size() == s.weight.size(),
      "particle arrays of different sizes");
  PF_FUZZ_CHECK(report.updated != (report.skip_reason != pf::SkipReason::kNone),
                "skipped without a reason, or updated with one");
  if (!filter.isInitialized()) return;
  PF_FUZZ_CHECK(s.size() >= static_cast<std::size_t>(p.kld.min_particles) &&
                    s.size() <= static_cast<std::size_t>(p.kld.max_particles),
                "%zu particles outside [%d, %d]", s.size(), p.kld.min_particles,
                p.kld.max_particles);
  double total = 0.0;
  for (double w : s.weight) {
    PF_FUZZ_CHECK(std::isfinite(w) && w >= 0.0, "weight %g", w);
    total += w;
  }
  PF_FUZZ_CHECK(std::fabs(total - 1.0) < 1e-6, "weights sum to %.17g", total);
  if (report.updated) {
    PF_FUZZ_CHECK(!filter.estimate().clusters.empty(), "an update without a cluster");
    PF_FUZZ_CHECK(filter.mapToOdom().has_value(), "an update without map -> odom");
  }
  if (report.refinement.accepted) {
    const pf::ScanRefinerParams& r = p.refiner;
    PF_FUZZ_CHECK(report.refinement.pose.isFinite() && report.refinement.covariance.allFinite(),
                  "a non-finite refinement");
    PF_FUZZ_CHECK(report.refinement.translation <= r.max_translation &&
                      std::fabs(report.refinement.rotation) <= r.max_rotation,
                  "a refinement beyond its bounds: %g m, %g rad", report.refinement.translation,
                  report.refinement.rotation);
  }
  (void)filter.mapToOdom();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  Input in(data, size);

  const pf::ParticleFilterParams params = readParams(in);
  logParams(params);
  std::unique_ptr<pf::ParticleFilter> filter;
  try {
    filter = std::make_unique<pf::ParticleFilter>(params);
  } catch (const std::invalid_argument& e) {
    PF_FUZZ_CHECK(std::strstr(e.what(), "invalid parameter") != nullptr, "unclear message: %s",
                  e.what());
    return 0;
  }

  // Before a map: updates are skipped, global localization refuses.
  {
    const pf::UpdateReport r = filter->update({}, pf::LaserScan{});
    PF_FUZZ_CHECK(!r.updated && r.skip_reason == pf::SkipReason::kNoMap, "update without a map");
    bool threw = false;
    try {
      filter->initializeUniform();
    } catch (const std::logic_error&) {
      threw = true;
    }
    PF_FUZZ_CHECK(threw, "initializeUniform without a map did not throw");
  }

  const std::unique_ptr<pf::OccupancyGrid> grid = readMap(in);
  if (!grid) return 0;
  // Parameters that passed validate() must be accepted by the parts too: no catch.
  const pf::LikelihoodFieldModel model(*grid, params.sensor);
  filter->setMap(*grid);

  // Initialisation.
  const uint8_t init = in.u8();
  switch (init % 4) {
    case 0:
    case 2: {
      pf::Pose2 mean = readPose(in, 25.0, 4.0);
      if (init % 4 == 2 && !grid->freeCells().empty()) {
        // Near a free cell, where the map has something to say.
        const int cell = grid->freeCells()[in.u8() % grid->freeCells().size()];
        grid->cellToWorld({cell % grid->width(), cell / grid->width()}, &mean.x, &mean.y);
      }
      Eigen::Matrix3d cov;
      cov(0, 0) = in.num(0.0, 0.5);
      cov(1, 1) = in.num(0.0, 0.5);
      cov(2, 2) = in.num(0.0, 0.5);
      cov(0, 1) = cov(1, 0) = in.num(-0.05, 0.05);
      cov(0, 2) = cov(2, 0) = in.num(-0.05, 0.05);
      cov(1, 2) = cov(2, 1) = in.num(-0.05, 0.05);
      if (init & 0x80) cov(2, 0) += in.num(-1.0, 1.0);  // not symmetric
      PF_FUZZ_LOG("initializeGaussian at (%g, %g, %g), cov diag %g %g %g", mean.x, mean.y, mean.yaw,
                  cov(0, 0), cov(1, 1), cov(2, 2));
      try {
        filter->initializeGaussian(mean, cov);
        PF_FUZZ_CHECK(
            filter->particles().size() == static_cast<std::size_t>(params.kld.max_particles),
            "%zu particles after initializeGaussian", filter->particles().size());
      } catch (const std::invalid_argument& e) {
        PF_FUZZ_CHECK(std::strstr(e.what(), "initial") != nullptr, "unclear message: %s", e.what());
      }
      break;
    }
    case 1:
      PF_FUZZ_LOG("initializeUniform over %zu free cells", grid->freeCells().size());
      try {
        filter->initializeUniform();
        for (std::size_t i = 0; i < filter->particles().size(); ++i) {
          const pf::Pose2 q = filter->particles().pose(i);
          PF_FUZZ_CHECK(q.isFinite(), "non-finite particle after initializeUniform");
        }
      } catch (const std::logic_error& e) {
        PF_FUZZ_CHECK(grid->freeCells().empty(), "initializeUniform threw with free cells: %s",
                      e.what());
      }
      break;
    default:
      break;  // uninitialised: updates must say so
  }

  pf::Pose2 odom = readPose(in, 5.0, 4.0);
  pf::LaserScan scan = readScan(in);
  PF_FUZZ_LOG("odometry (%g, %g, %g)", odom.x, odom.y, odom.yaw);
  logScan(scan);
  const int steps = 1 + in.u8() % 10;
  for (int step = 0; step < steps && !in.exhausted(); ++step) {
    const uint8_t op = in.u8();
    switch (op % 10) {
      case 0:
      case 1:
      case 2: {  // a small move, sometimes with special values
        const pf::Pose2 d = readPose(in, 0.5, 0.7);
        odom = pf::compose(odom, d);
        break;
      }
      case 3:  // an absolute odometry pose: jumps, NaN, 1e300
        odom = {in.num(-1e3, 1e3), in.num(-1e3, 1e3), in.num(-10.0, 10.0)};
        break;
      case 4:
        scan = readScan(in);
        break;
      case 5:
        spoilScan(in, &scan);
        break;
      case 6:
        filter->requestNoMotionUpdate();
        break;
      case 7:
        filter->setMap(*grid);
        break;
      case 8:
        try {
          filter->initializeUniform();
        } catch (const std::logic_error& e) {
          PF_FUZZ_CHECK(grid->freeCells().empty(), "initializeUniform threw: %s", e.what());
        }
        break;
      default:
        filter->requestNoMotionUpdate();
        odom = pf::compose(odom, readPose(in, 0.05, 0.1));
        break;
    }

    PF_FUZZ_LOG("step %d: op %d, odometry (%g, %g, %g)", step, op % 10, odom.x, odom.y, odom.yaw);
    if (op % 10 == 4 || op % 10 == 5) logScan(scan);
    checkBeams(scan, params);
    const pf::PreparedScan prepared = model.prepare(scan);
    PF_FUZZ_CHECK(prepared.x.size() == prepared.y.size(), "prepared arrays differ");
    if (!pf::validateScan(scan) && prepared.size() > 0 && odom.isFinite()) {
      (void)model.logLikelihood(prepared, odom);
    }

    const pf::UpdateReport report = filter->update(odom, scan);
    PF_FUZZ_LOG("  update: %s (%d beams, %zu particles)",
                report.updated ? "updated" : pf::skipMessage(report).c_str(), report.beams_used,
                report.particles);
    if (!odom.isFinite()) {
      PF_FUZZ_CHECK(!report.updated, "updated with non-finite odometry");
    }
    if (const auto why = pf::validateScan(scan)) {
      PF_FUZZ_CHECK(!why->empty(), "empty scan rejection");
      PF_FUZZ_CHECK(!report.updated, "updated with a bad scan: %s", why->c_str());
    }
    checkFilter(*filter, report);
    (void)pf::estimatePose(filter->particles(), params.clusters);
  }
  return 0;
}

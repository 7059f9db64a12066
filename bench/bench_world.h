// The synthetic world of the benchmarks (bench/*_benchmark.cc): a room of
// pillars, scans with every beam valid or ray cast on it, particles
// scattered around one pose. Fixed, so that the figures depend only on the
// code and the machine.
#pragma once

#include <cstddef>

#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/util/pose2.h"
#include "pf_localization/core/util/random.h"

namespace pf_bench {

/// A side x side map at 0.05 m with walls on the border and a pillar every 2 m.
pf::OccupancyGrid pillarMap(int side);

/// A full turn of `beams` beams, every one valid, ranges 1 to 4 m.
pf::LaserScan fullScan(int beams);

/// `n` uniformly weighted particles around (10, 10), heading anywhere.
pf::ParticleSet scatter(std::size_t n, pf::Random* random);

/// A scan of `beams` beams over a full turn, ray cast on `grid` from `pose`
/// in steps of 5 mm: every end point lies on a wall or a pillar.
pf::LaserScan castScan(const pf::OccupancyGrid& grid, const pf::Pose2& pose, int beams);

}  // namespace pf_bench

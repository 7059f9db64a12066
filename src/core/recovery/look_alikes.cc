#include "pf_localization/core/recovery/look_alikes.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <unsupported/Eigen/FFT>
#include <utility>

#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/sensor/sensor_update.h"
#include "pf_localization/core/util/packed_flags.h"

namespace pf {
namespace {

// The coarse grid the correlations run on: cells of at least kCoarseCell,
// wider when the map would need more than kMaxCoarseSide of them along a
// side (a 4000 x 4000 map at 0.05 m takes 0.4 m cells, its FFTs 1000 x 1000).
constexpr double kCoarseCell = 0.2;  // m
constexpr int kMaxCoarseSide = 512;
// Refinement samples at most this many obstacle cells per candidate.
constexpr std::size_t kRefineSamples = 600;

// Single precision: the correlations count cells (at most a few 10^5), far
// within a float's 24 bits, and the FFTs take half the time.
using Complex = std::complex<float>;

// The smallest size >= n with no prime factor above 5 (kissfft's fast radices).
int fftSize(int n) {
  for (int m = std::max(n, 1);; ++m) {
    int r = m;
    for (int p : {2, 3, 5}) {
      while (r % p == 0) r /= p;
    }
    if (r == 1) return m;
  }
}

// In-place 2D FFT of a p x p row-major grid.
void fft2(std::vector<Complex>* grid, int p, bool inverse) {
  Eigen::FFT<float> fft;
  std::vector<Complex> in(p), out(p);
  for (int pass = 0; pass < 2; ++pass) {
    for (int line = 0; line < p; ++line) {
      // pass 0: rows; pass 1: columns
      for (int i = 0; i < p; ++i) in[i] = (*grid)[pass == 0 ? line * p + i : i * p + line];
      if (inverse) {
        fft.inv(out, in);
      } else {
        fft.fwd(out, in);
      }
      for (int i = 0; i < p; ++i) (*grid)[pass == 0 ? line * p + i : i * p + line] = out[i];
    }
  }
}

// A candidate motion in the grid's own frame (metres from its lower-left
// corner along its axes): u -> R(yaw) u + t.
struct Candidate {
  Pose2 motion;
  double score = 0.0;
};

// Local maxima of `values` (p x p, wrapping) at or above `threshold`, kept
// when `keep(ix, iy)`.
template <typename Keep>
void peaks(const std::vector<double>& values, int p, double threshold, Keep keep,
           std::vector<std::pair<double, int>>* out) {
  for (int y = 0; y < p; ++y) {
    for (int x = 0; x < p; ++x) {
      const double v = values[y * p + x];
      if (v < threshold || !keep(x, y)) continue;
      bool peak = true;
      for (int dy = -1; dy <= 1 && peak; ++dy) {
        for (int dx = -1; dx <= 1 && peak; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const double w = values[((y + dy + p) % p) * p + (x + dx + p) % p];
          // Ties go to the first in scan order.
          peak = w < v || (w == v && (dy > 0 || (dy == 0 && dx > 0)));
        }
      }
      if (peak) out->emplace_back(v, y * p + x);
    }
  }
}

// The cells within one cell of an obstacle, a bit each: what the search
// below reads, 6 MB on a 200 x 600 m floor where the field's classes are 96.
class NearObstacle {
 public:
  explicit NearObstacle(const DistanceField& field) : grid_(field.grid()) {
    // Within 1.01 cells: a class below `within` (distance_field.h).
    const std::size_t within = field.classesWithin(1.01 * grid_.resolution());
    // A word at a time, four cells at a time in a register where the bound
    // allows (packed_flags.h).
    bits_.assign((field.size() + 63) / 64, 0);
    const uint16_t* classes = field.classes();
    const std::size_t packed = within <= 0x8000 ? field.size() / 64 : 0;
    for (std::size_t w = 0; w < packed; ++w) {
      bits_[w] = flagsBelow(classes + 64 * w, static_cast<unsigned>(within));
    }
    for (std::size_t i = packed * 64; i < field.size(); ++i) {
      bits_[i / 64] |= static_cast<uint64_t>(classes[i] < within) << (i % 64);
    }
  }
  const OccupancyGrid& grid() const { return grid_; }
  /// The bits of cells (x0 + k, y), k in [0, n), as bit k of one word
  /// (0 off the map); n at most 64.
  uint64_t row(int x0, int y, int n) const {
    const int lo = std::max(x0, 0), hi = std::min(x0 + n, grid_.width());
    if (y < 0 || y >= grid_.height() || lo >= hi) return 0;
    const std::size_t i = static_cast<std::size_t>(y) * grid_.width() + lo;
    const std::size_t word = i / 64, shift = i % 64;
    uint64_t v = bits_[word] >> shift;
    if (shift != 0 && word + 1 < bits_.size()) v |= bits_[word + 1] << (64 - shift);
    const int k = hi - lo;
    if (k < 64) v &= (uint64_t{1} << k) - 1;
    return v << (lo - x0);
  }

 private:
  const OccupancyGrid& grid_;
  std::vector<uint64_t> bits_;
};

// The best of `candidate` moved by multiples of `step` cells within
// +-reach cells, scored by the share of `samples` (grid-frame points) each
// move puts within one cell of an obstacle. A move by whole cells moves a
// sample's cell by as many (samples are cell centres, and candidates whole
// cells or half turns about cell corners: a sample is half a cell from any
// boundary), so each sample reads the row of bits under each move's row at
// once. The first best move in row order wins.
Candidate bestOffset(const NearObstacle& near, const std::vector<Eigen::Vector2d>& samples,
                     const Pose2& candidate, int reach, int step) {
  const double res = near.grid().resolution();
  const int side = 2 * (reach / step) + 1, span = 2 * reach + 1;
  std::vector<std::size_t> hits(static_cast<std::size_t>(side) * side, 0);
  const double c = std::cos(candidate.yaw), s = std::sin(candidate.yaw);
  for (const Eigen::Vector2d& u : samples) {
    const double x = c * u.x() - s * u.y() + candidate.x, y = s * u.x() + c * u.y() + candidate.y;
    const int cx = static_cast<int>(std::floor(x / res)),
              cy = static_cast<int>(std::floor(y / res));
    for (int r = 0; r < side; ++r) {
      const int dy = r * step - reach;
      std::size_t* row_hits = &hits[static_cast<std::size_t>(r) * side];
      if (span <= 64) {
        const uint64_t bits = near.row(cx - reach, cy + dy, span);
        if (bits == 0) continue;
        for (int k = 0; k < side; ++k) row_hits[k] += (bits >> (k * step)) & 1;
      } else {
        for (int k = 0; k < side; ++k) {
          row_hits[k] += near.row(cx + k * step - reach, cy + dy, 1);
        }
      }
    }
  }
  Candidate best{candidate, -1.0};
  for (std::size_t k = 0; k < hits.size(); ++k) {
    const double score =
        samples.empty() ? 0.0 : static_cast<double>(hits[k]) / static_cast<double>(samples.size());
    const int dx = static_cast<int>(k % side) * step - reach;
    const int dy = static_cast<int>(k / side) * step - reach;
    if (score > best.score)
      best = {{candidate.x + dx * res, candidate.y + dy * res, candidate.yaw}, score};
  }
  return best;
}

// `candidate` moved by whole cells within +-reach, to the best overlap: a
// search on every step-th cell with `some` of the samples (a quarter), then
// every cell around its best with them all.
Candidate refine(const NearObstacle& near, const std::vector<Eigen::Vector2d>& samples,
                 const std::vector<Eigen::Vector2d>& some, const Pose2& candidate, int reach) {
  const int step = std::max(1, reach / 4);
  const Candidate rough = bestOffset(near, some, candidate, reach - reach % step, step);
  return bestOffset(near, samples, rough.motion, step, 1);
}

// The map's obstacle cells, by linear index (four bytes each, not a
// centre's sixteen: a warehouse floor has millions).
std::vector<std::uint32_t> obstacleCells(const OccupancyGrid& grid) {
  std::vector<std::uint32_t> obstacles;
  const std::vector<int8_t>& cells = grid.data();
  const auto occupied = [&cells](std::size_t i) {
    return OccupancyGrid::classify(cells[i]) == CellState::kOccupied;
  };
  // 64 cells at a time, as the bits of a word (packed_flags.h): most are not
  // obstacles. Occupied is [kOccupiedMin, 127].
  static_assert(OccupancyGrid::kOccupiedMin > 0, "occupied values are positive");
  const std::size_t whole = cells.size() / 64;
  for (std::size_t w = 0; w < whole; ++w) {
    uint64_t bits = flagsInRange(cells.data() + 64 * w, OccupancyGrid::kOccupiedMin, 127);
    for (; bits != 0; bits &= bits - 1) {
      obstacles.push_back(static_cast<std::uint32_t>(64 * w + __builtin_ctzll(bits)));
    }
  }
  for (std::size_t i = whole * 64; i < cells.size(); ++i) {
    if (occupied(i)) obstacles.push_back(static_cast<std::uint32_t>(i));
  }
  return obstacles;
}

// The grid-frame centre of obstacle cell `i`.
Eigen::Vector2d centreOf(std::uint32_t i, const OccupancyGrid& grid) {
  const std::uint32_t w = static_cast<std::uint32_t>(grid.width());
  return {(static_cast<int>(i % w) + 0.5) * grid.resolution(),
          (static_cast<int>(i / w) + 0.5) * grid.resolution()};
}

// The peaks of the coarse grid's autocorrelation (shifts) and
// self-convolution (half turns) holding kMinSymmetryOverlap of its obstacle
// cells, strongest first, at most kMaxSymmetries; `cell` m a side.
std::vector<Candidate> coarsePeaks(const std::vector<std::uint32_t>& obstacles,
                                   const OccupancyGrid& grid, int cw, int ch, double cell) {
  const int p = fftSize(2 * std::max(cw, ch));
  std::vector<Complex> spectrum(static_cast<std::size_t>(p) * p);
  for (std::uint32_t i : obstacles) {
    const Eigen::Vector2d u = centreOf(i, grid);
    const int cx = static_cast<int>(u.x() / cell), cy = static_cast<int>(u.y() / cell);
    spectrum[static_cast<std::size_t>(cy) * p + cx] = 1.0;
  }
  double occupied = 0.0;
  for (const Complex& v : spectrum) occupied += v.real();
  fft2(&spectrum, p, false);
  // Shifts: the autocorrelation sum_u o(u) o(u + s), of spectrum |F|^2; half
  // turns: the self-convolution sum_u o(u) o(k - u), o's point symmetry
  // about k / 2, of spectrum F^2. Both are real, so one inverse transform of
  // |F|^2 + i F^2 gives the first as its real part, the second as its imaginary.
  for (Complex& v : spectrum) v = std::norm(v) + Complex(0.0f, 1.0f) * (v * v);
  fft2(&spectrum, p, true);
  std::vector<double> shift_values(spectrum.size()), turn_values(spectrum.size());
  for (std::size_t i = 0; i < spectrum.size(); ++i) {
    shift_values[i] = spectrum[i].real();
    turn_values[i] = spectrum[i].imag();
  }

  const double threshold = LookAlikes::kMinSymmetryOverlap * occupied;
  const auto signed_index = [p](int i) { return i <= p / 2 ? i : i - p; };
  std::vector<std::pair<double, int>> shift_peaks, turn_peaks;
  peaks(
      shift_values, p, threshold,
      [&](int x, int y) {
        return std::hypot(signed_index(x), signed_index(y)) * cell >= LookAlikes::kMinShift;
      },
      &shift_peaks);
  peaks(
      turn_values, p, threshold, [](int, int) { return true; }, &turn_peaks);
  std::vector<Candidate> candidates;
  for (const auto& [v, i] : shift_peaks) {
    candidates.push_back({{signed_index(i % p) * cell, signed_index(i / p) * cell, 0.0}, v});
  }
  for (const auto& [v, i] : turn_peaks) {
    // Coarse cell c maps to k - c: its centre (c + 1/2) cell to (k - c + 1/2) cell.
    candidates.push_back({{(i % p + 1) * cell, (i / p + 1) * cell, M_PI}, v});
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  if (candidates.size() > LookAlikes::kMaxSymmetries) {
    candidates.resize(LookAlikes::kMaxSymmetries);
  }
  return candidates;
}

}  // namespace

std::vector<MapSymmetry> findMapSymmetries(const DistanceField& field) {
  const OccupancyGrid& grid = field.grid();
  const int w = grid.width(), h = grid.height();
  const double res = grid.resolution();
  if (grid.data().size() > std::numeric_limits<std::uint32_t>::max()) return {};
  const std::vector<std::uint32_t> obstacles = obstacleCells(grid);
  if (obstacles.empty()) return {};

  int f = std::max(1, static_cast<int>(std::ceil(kCoarseCell / res - 1e-9)));
  while ((w + f - 1) / f > kMaxCoarseSide || (h + f - 1) / f > kMaxCoarseSide) ++f;
  const std::vector<Candidate> candidates =
      coarsePeaks(obstacles, grid, (w + f - 1) / f, (h + f - 1) / f, f * res);

  std::vector<Eigen::Vector2d> samples;
  const std::size_t stride = std::max<std::size_t>(1, obstacles.size() / kRefineSamples);
  for (std::size_t i = 0; i < obstacles.size(); i += stride) {
    samples.push_back(centreOf(obstacles[i], grid));
  }
  std::vector<Eigen::Vector2d> some;
  for (std::size_t i = 0; i < samples.size(); i += 4) some.push_back(samples[i]);
  if (candidates.empty()) return {};
  const NearObstacle near(field);
  std::vector<Candidate> refined;
  for (const Candidate& c : candidates) {
    const Candidate r = refine(near, samples, some, c.motion, f);
    const bool is_shift = r.motion.yaw == 0.0;
    if (r.score < LookAlikes::kMinSymmetryOverlap) continue;
    if (is_shift && std::hypot(r.motion.x, r.motion.y) < LookAlikes::kMinShift) continue;
    const bool seen = std::any_of(refined.begin(), refined.end(), [&](const Candidate& o) {
      return o.motion.yaw == r.motion.yaw &&
             std::hypot(o.motion.x - r.motion.x, o.motion.y - r.motion.y) < 2.5 * res;
    });
    if (!seen) refined.push_back(r);
  }
  std::sort(refined.begin(), refined.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  if (refined.size() > LookAlikes::kMaxSymmetries) refined.resize(LookAlikes::kMaxSymmetries);

  // Grid frame to world: world = origin (+) u, so the world motion is
  // origin (+) m (+) origin^-1.
  std::vector<MapSymmetry> out;
  for (const Candidate& c : refined) {
    out.push_back({compose(compose(grid.origin(), c.motion), inverse(grid.origin())), c.score});
  }
  return out;
}

void LookAlikes::setSymmetries(std::vector<MapSymmetry> symmetries) {
  symmetries_ = std::move(symmetries);
  restart();
}

void LookAlikes::restart() { streaks_.assign(symmetries_.size(), 0); }

namespace {

// The scans' log-likelihood at each of `poses`, as the filter weighs a
// particle there (groupLogLikelihoods). No search around them: the
// symmetries are refined to a cell, and half a cell (2.5 cm) moves 60 beams'
// tempered log-likelihood by about 0.4 at sigma_hit 0.2 m, far below the margins.
std::vector<double> fitsAt(const SensorModel& model, const std::vector<PreparedScan>& scans,
                           const std::vector<Pose2>& poses) {
  ParticleSet placed;
  placed.resize(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) placed.setPose(i, poses[i]);
  std::vector<double> fits, scratch;
  groupLogLikelihoods(model, scans, placed, &fits, &scratch);
  return fits;
}

}  // namespace

void LookAlikes::lookAlikesOf(const OccupancyGrid& grid, const Pose2& pose,
                              std::vector<Pose2>* poses, std::vector<std::size_t>* index) const {
  for (std::size_t i = 0; i < symmetries_.size(); ++i) {
    const Pose2 twin = compose(symmetries_[i].motion, pose);
    if (!grid.isFreeAt(twin.x, twin.y)) continue;
    poses->push_back(twin);
    if (index) index->push_back(i);
  }
}

namespace {

// Beams that pass a mapped obstacle or leave the map, placed from `pose`.
std::size_t throughOrOff(const MapEvidence& evidence, const std::vector<PreparedScan>& scans,
                         const Pose2& pose) {
  const EvidenceCounts c = evidence.count(scans, pose);
  return c.throughMap() + c.off_map;
}

// Whether the scans placed at the look-alike `place` pass the map's obstacles
// or leave the map no more often than at `estimate` (kSeenMargin of the beams
// more at most). A changed map can make a place fit better only by beams
// that would have to see through its walls there.
bool seenAsWell(const MapEvidence& evidence, const std::vector<PreparedScan>& scans,
                const Pose2& estimate, const Pose2& place) {
  const double beams = static_cast<double>(beamCount(scans));
  return static_cast<double>(throughOrOff(evidence, scans, place)) <=
         static_cast<double>(throughOrOff(evidence, scans, estimate)) +
             LookAlikes::kSeenMargin * beams;
}

}  // namespace

LookAlikeView LookAlikes::judge(const SensorModel& model, const std::vector<PreparedScan>& scans,
                                const Pose2& estimate, const MapEvidence* evidence) {
  LookAlikeView view;
  if (symmetries_.empty()) return view;
  std::vector<Pose2> poses{estimate};  // the estimate, then its look-alikes in free space
  std::vector<std::size_t> index;      // each look-alike's symmetry
  lookAlikesOf(model.field().grid(), estimate, &poses, &index);
  const std::vector<double> fits = fitsAt(model, scans, poses);
  view.fit = fits[0];
  view.best_fit = -std::numeric_limits<double>::infinity();
  for (std::size_t j = 1; j < fits.size(); ++j) view.best_fit = std::max(view.best_fit, fits[j]);
  // Better: clearly better than the estimate, and as good as the best look-alike.
  const double better = std::max(view.fit + kBetterMargin, view.best_fit - kAsGoodMargin);
  std::vector<int> streaks(symmetries_.size(), 0);
  for (std::size_t j = 1; j < fits.size(); ++j) {
    const std::size_t i = index[j - 1];
    if (fits[j] >= view.fit - kAsGoodMargin) {
      ++view.as_good;
      view.places.push_back({poses[j], fits[j]});
    }
    if (fits[j] >= better && (!evidence || seenAsWell(*evidence, scans, estimate, poses[j]))) {
      streaks[i] = streaks_[i] + 1;
      if (streaks[i] >= kBetterUpdates) view.better.push_back(symmetries_[i].motion);
    }
  }
  streaks_ = std::move(streaks);
  return view;
}

std::vector<LookAlikePlace> LookAlikes::placesAround(const SensorModel& model,
                                                     const std::vector<PreparedScan>& scans,
                                                     const std::vector<Pose2>& held,
                                                     double min_fit) const {
  std::vector<Pose2> poses;
  for (const Pose2& place : held) lookAlikesOf(model.field().grid(), place, &poses, nullptr);
  std::vector<LookAlikePlace> out;
  if (poses.empty()) return out;
  const std::vector<double> fits = fitsAt(model, scans, poses);
  for (std::size_t j = 0; j < poses.size(); ++j)
    if (fits[j] >= min_fit) out.push_back({poses[j], fits[j]});
  return out;
}

}  // namespace pf

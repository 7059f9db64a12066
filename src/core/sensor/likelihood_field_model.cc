#include "pf_localization/core/sensor/likelihood_field_model.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/util/fast_math.h"
#include "pf_localization/core/util/parameter_table.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {

const ParameterTable<LikelihoodFieldModelParams>& likelihoodFieldParameters() {
  using P = LikelihoodFieldModelParams;
  using I = ParamInfo;
  static const ParameterTable<P> table = {
      member(&P::max_beams, I("laser_max_beams", "beams", "beams used per scan, evenly spaced")
                                .in(Range::atLeast(1))
                                .amcl()
                                .live(0, 10000)),
      member(&P::range_min, I("laser_min_range", "m", "ignore beams shorter than this")
                                .in(Range::atLeast(0))
                                .withNote("0 or less: the scan's range_min")
                                .amcl()
                                .live(-1, 100)),
      member(&P::range_max, I("laser_max_range", "m", "ignore beams at or beyond this")
                                .in(Range::atLeast(0))
                                .withNote("0 or less: the scan's range_max")
                                .amcl()
                                .live(-1, 100)),
      member(&P::z_hit, I("laser_z_hit", "", "weight of the Gaussian hit component")
                            .in(Range::atLeast(0))
                            .amcl()
                            .live(0, 1)),
      member(&P::z_rand, I("laser_z_rand", "", "weight of the uniform random component")
                             .in(Range::atLeast(0))
                             .amcl()
                             .live(0, 1)),
      member(&P::sigma_hit, I("laser_sigma_hit", "m", "std dev of the hit component")
                                .in(Range::above(0))
                                .amcl()
                                .live(0, 10)),
      member(&P::max_distance, I("laser_likelihood_max_dist", "m", "distance field cap")
                                   .in(Range::above(0))
                                   .amcl()
                                   .live(0, 20)),
      member(&P::likelihood_exponent,
             I("laser_likelihood_exponent", "",
               "power of the scan likelihood: a scan's beams are not independent, and their plain "
               "product (1) is overconfident")
                 .in(Range::openClosed(0, 1))
                 .live(0, 1)),
      member(&P::beam_skip,
             I("do_beamskip", "", "likelihood_field_prob: skip beams most particles disagree with")
                 .amcl()
                 .live()),
  };
  return table;
}

const ParameterTable<LikelihoodFieldModelParams>& beamSkipParameters() {
  using P = LikelihoodFieldModelParams;
  using I = ParamInfo;
  static const ParameterTable<P> table = {
      member(&P::beam_skip_distance,
             I("beam_skip_distance", "m", "an end point this close to an obstacle agrees")
                 .in(Range::above(0))
                 .amcl()
                 .live(0.001, 5)),
      member(&P::beam_skip_threshold,
             I("beam_skip_threshold", "", "share of the particles that must agree on a beam")
                 .in(Range::closed(0, 1))
                 .amcl()
                 .live(0, 1)),
      // amcl reads only the misspelt name; configurations written for it exist.
      member(&P::beam_skip_error_threshold,
             I("beam_skip_error_threshold", "", "skip nothing when this share would be skipped")
                 .in(Range::closed(0, 1))
                 .amclAlias("beam_skip_error_threshold_")
                 .live(0, 1)),
  };
  return table;
}

void validate(const LikelihoodFieldModelParams& params) {
  checkRanges(likelihoodFieldParameters(), params);
  // Unused, so unchecked, while skipping is off (as in amcl).
  if (params.beam_skip) checkRanges(beamSkipParameters(), params);
  requireParameter(params.z_hit + params.z_rand > 0.0, "laser_z_hit + laser_z_rand", "> 0",
                   params.z_hit + params.z_rand);
}

LikelihoodFieldModel::LikelihoodFieldModel(OccupancyGrid grid,
                                           const LikelihoodFieldModelParams& params,
                                           TableLayout layout)
    : params_((validate(params), params)),
      field_(std::make_shared<const DistanceField>(std::move(grid), params.max_distance,
                                                   params.threads)),
      cell_tables_(layout == TableLayout::kBySize ? field_->size() <= DistanceField::kMaxFloatCells
                                                  : layout == TableLayout::kPerCell) {
  if (!params.beam_skip) return;
  const OccupancyGrid& map = field_->grid();
  const int stride = map.width() + 2;
  near_.assign(static_cast<std::size_t>(stride) * (map.height() + 2), 0);
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      // amcl's test: occ_dist < beam_skip_distance (0 on an occupied cell).
      const float occ_dist = field_->distance(static_cast<std::size_t>(y) * map.width() + x);
      near_[static_cast<std::size_t>(y + 1) * stride + x + 1] =
          occ_dist < params.beam_skip_distance ? 1 : 0;
    }
  }
}

LikelihoodFieldModel::LikelihoodFieldModel(const LikelihoodFieldModel& model, double sigma_hit)
    : params_(model.params_),
      field_(model.field_),
      cell_tables_(model.cell_tables_),
      near_(model.near_) {
  params_.sigma_hit = sigma_hit;
  validate(params_);
}

std::unique_ptr<SensorModel> LikelihoodFieldModel::smoothed(double sigma_hit) const {
  return std::unique_ptr<SensorModel>(new LikelihoodFieldModel(*this, sigma_hit));
}

double LikelihoodFieldModel::beamLogLikelihood(double distance, double range_max) const {
  const double s = params_.sigma_hit;
  const double gauss = std::exp(-0.5 * distance * distance / (s * s)) / (s * std::sqrt(2.0 * M_PI));
  return std::log(params_.z_hit * gauss + params_.z_rand / range_max);
}

PreparedScan LikelihoodFieldModel::prepare(const LaserScan& scan, int max_beams) const {
  return prepareScan(scan, max_beams, params_.range_min, params_.range_max,
                     field_->grid().resolution());
}

const std::vector<float>& LikelihoodFieldModel::table(double range_max) const {
  return tables_.get(range_max, [this](double r, std::vector<float>* out) { buildTable(r, out); });
}

void LikelihoodFieldModel::buildTable(double range_max, std::vector<float>* out) const {
  // A value per class of the field's cells (distance_field.h), and past
  // them one for a point off the map.
  const std::vector<float>& distances = field_->classDistances();
  const double k = params_.likelihood_exponent;
  std::vector<float> per_class(distances.size() + 1);
  for (std::size_t c = 0; c < distances.size(); ++c) {
    per_class[c] = static_cast<float>(k * beamLogLikelihood(distances[c], range_max));
  }
  per_class.back() = static_cast<float>(k * beamLogLikelihood(field_->maxDistance(), range_max));
  if (!cellTables()) {
    *out = std::move(per_class);
    return;
  }
  // Spread over the cells, with a one-cell border off the map.
  const OccupancyGrid& grid = field_->grid();
  const std::size_t w = static_cast<std::size_t>(grid.width()), stride = w + 2;
  out->assign(stride * (grid.height() + 2), per_class.back());
  const uint16_t* classes = field_->classes();
  for (std::size_t y = 0; y < static_cast<std::size_t>(grid.height()); ++y) {
    float* row = out->data() + (y + 1) * stride + 1;
    for (std::size_t x = 0; x < w; ++x) row[x] = per_class[classes[y * w + x]];
  }
}

double LikelihoodFieldModel::logLikelihood(const PreparedScan& scan, const Pose2& pose) const {
  ParticleSet one;
  one.resize(1);
  one.setPose(0, pose);
  const float* lookup = table(scan.range_max).data();
  const float inv_res = static_cast<float>(1.0 / field_->grid().resolution());
  std::vector<float> bx(scan.size()), by(scan.size());
  for (std::size_t b = 0; b < scan.size(); ++b) {
    bx[b] = scan.x[b] * inv_res;
    by[b] = scan.y[b] * inv_res;
  }
  std::vector<double> out;
  score(lookup, bx.data(), by.data(), scan.size(), one, &out);
  return out[0];
}

namespace {

// What scoring a particle needs, in the grid's cell units. The end points
// are placed on the map with a one-cell border all round that stands for
// "off the map".
struct ScoringFrame {
  // Per class of cell, the log-likelihood, off the map last; or, when
  // classes is nullptr, per cell of the map and its border.
  const float* table;
  const uint16_t* classes;  // per cell (DistanceField::classes), or nullptr
  int off_map;              // the table's last entry
  int width, height;        // of the map
  int stride;               // of the map with its border
  float max_x, max_y;       // last border column and row
  float inv_res;
  Pose2 origin;
  double origin_cos, origin_sin;
  const float* bx;  // beam end points in the robot frame, in cells
  const float* by;
  std::size_t beams;
};

// The particle `i` in the grid's frame, in cells, shifted by the border;
// the origin's rotation is applied here, once per particle.
inline void particleInCells(const ScoringFrame& f, const ParticleSet& particles, std::size_t i,
                            float* px, float* py) {
  const double dx = particles.x[i] - f.origin.x, dy = particles.y[i] - f.origin.y;
  *px = static_cast<float>((f.origin_cos * dx + f.origin_sin * dy) * f.inv_res) + 1.0f;
  *py = static_cast<float>((-f.origin_sin * dx + f.origin_cos * dy) * f.inv_res) + 1.0f;
}

// The table cell of the end point (ux, uy) (robot frame, cells) seen from a
// particle at (px, py) (from particleInCells) whose heading has the cosine
// `c` and the sine `s`. Clamping before truncation sends every point
// outside the map to the border, and makes truncation equal floor for what
// remains. The comparisons are written so that NaN (from a particle at
// infinity) also lands in the border instead of becoming an undefined int.
inline void endPointColumnRow(const ScoringFrame& f, float px, float py, float c, float s, float ux,
                              float uy, int* column, int* row) {
  const float ex = px + c * ux - s * uy;
  const float ey = py + s * ux + c * uy;
  const float gx = ex > 0.0f ? std::min(ex, f.max_x) : 0.0f;
  const float gy = ey > 0.0f ? std::min(ey, f.max_y) : 0.0f;
  *column = static_cast<int>(gx);
  *row = static_cast<int>(gy);
}

inline int endPointCell(const ScoringFrame& f, float px, float py, float c, float s, float ux,
                        float uy) {
  int column, row;
  endPointColumnRow(f, px, py, c, s, ux, uy, &column, &row);
  return row * f.stride + column;
}

// The log-likelihood of endPointCell's cell: its class's on the map, the
// last entry's on the border.
inline float endPointValue(const ScoringFrame& f, float px, float py, float c, float s, float ux,
                           float uy) {
  int column, row;
  endPointColumnRow(f, px, py, c, s, ux, uy, &column, &row);
  if (!f.classes) return f.table[row * f.stride + column];
  const bool on = column > 0 && row > 0 && column <= f.width && row <= f.height;
  return f
      .table[on ? f.classes[static_cast<std::size_t>(row - 1) * f.width + column - 1] : f.off_map];
}

#if defined(__x86_64__)
// scoreParticles for blocks of eight particles, one per lane of an AVX2
// register, the beams one by one. Each particle's end points and its sum are
// endPointCell's operations in the same order (no fused multiply-add,
// the beams added in turn), so the scores are the same bits on any
// processor. Returns the first particle it did not score.
template <bool kByClass>
__attribute__((target("avx2"))) std::size_t scoreBlocksAvx2(
    const ScoringFrame& f, const ParticleSet& particles, const double* sin_yaw,
    const double* cos_yaw, std::size_t begin, std::size_t end, double* out) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256i zero_i = _mm256_setzero_si256();
  const __m256 max_x = _mm256_set1_ps(f.max_x), max_y = _mm256_set1_ps(f.max_y);
  const __m256i width = _mm256_set1_epi32(f.width), height = _mm256_set1_epi32(f.height);
  const __m256i one = _mm256_set1_epi32(1), low = _mm256_set1_epi32(0xFFFF);
  const __m256i off_map = _mm256_set1_epi32(f.off_map), all = _mm256_set1_epi32(-1);
  const __m256i stride = _mm256_set1_epi32(f.stride);
  const int* classes = reinterpret_cast<const int*>(f.classes);
  std::size_t i = begin;
  for (; i + 8 <= end; i += 8) {
    alignas(32) float px_l[8], py_l[8];
    for (std::size_t l = 0; l < 8; ++l) particleInCells(f, particles, i + l, &px_l[l], &py_l[l]);
    const __m256 px = _mm256_load_ps(px_l), py = _mm256_load_ps(py_l);
    const __m256 c = _mm256_set_m128(_mm256_cvtpd_ps(_mm256_loadu_pd(cos_yaw + i + 4)),
                                     _mm256_cvtpd_ps(_mm256_loadu_pd(cos_yaw + i)));
    const __m256 s = _mm256_set_m128(_mm256_cvtpd_ps(_mm256_loadu_pd(sin_yaw + i + 4)),
                                     _mm256_cvtpd_ps(_mm256_loadu_pd(sin_yaw + i)));
    __m256 sum = zero;
    for (std::size_t b = 0; b < f.beams; ++b) {
      const __m256 ux = _mm256_set1_ps(f.bx[b]), uy = _mm256_set1_ps(f.by[b]);
      const __m256 ex =
          _mm256_sub_ps(_mm256_add_ps(px, _mm256_mul_ps(c, ux)), _mm256_mul_ps(s, uy));
      const __m256 ey =
          _mm256_add_ps(_mm256_add_ps(py, _mm256_mul_ps(s, ux)), _mm256_mul_ps(c, uy));
      // endPointCell's clamp in two instructions, not three: min and max
      // return their second operand for NaN (and max for two zeros), so
      // NaN, zero and below all become +0, as there.
      const __m256 gx = _mm256_max_ps(_mm256_min_ps(max_x, ex), zero);
      const __m256 gy = _mm256_max_ps(_mm256_min_ps(max_y, ey), zero);
      __m256 v;
      if constexpr (kByClass) {
        // The column and row on the map (endPointValue): the border is -1
        // or the width (height), where the cell's class is off_map.
        const __m256i x = _mm256_sub_epi32(_mm256_cvttps_epi32(gx), one);
        const __m256i y = _mm256_sub_epi32(_mm256_cvttps_epi32(gy), one);
        const __m256i off = _mm256_or_si256(
            _mm256_or_si256(_mm256_cmpgt_epi32(zero_i, x), _mm256_cmpgt_epi32(zero_i, y)),
            _mm256_or_si256(_mm256_cmpeq_epi32(x, width), _mm256_cmpeq_epi32(y, height)));
        const __m256i cell = _mm256_add_epi32(_mm256_mullo_epi32(y, width), x);
        // Two gathers for the eight cells: their classes (four bytes at two-
        // byte steps, the upper half masked off; the map's lanes only),
        // then the classes' values.
        const __m256i cls = _mm256_and_si256(
            _mm256_mask_i32gather_epi32(off_map, classes, cell, _mm256_xor_si256(off, all), 2),
            low);
        v = _mm256_i32gather_ps(f.table, cls, 4);
      } else {
        const __m256i cell = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_cvttps_epi32(gy), stride),
                                              _mm256_cvttps_epi32(gx));
        // One gather for the eight cells: 0.55 ns per particle and beam
        // here, against 1.25 ns with eight scalar loads, or one particle at
        // a time.
        v = _mm256_i32gather_ps(f.table, cell, 4);
      }
      sum = _mm256_add_ps(sum, v);
    }
    alignas(32) float sum_l[8];
    _mm256_store_ps(sum_l, sum);
    for (std::size_t l = 0; l < 8; ++l) out[i + l] = sum_l[l];
  }
  return i;
}
#endif

// Scores particles [begin, end), whose headings in the grid's frame have
// the sines and cosines `sin_yaw` and `cos_yaw`: where the processor has
// AVX2, eight particles at a time (scoreBlocksAvx2), the rest one by one.
void scoreParticles(const ScoringFrame& f, const ParticleSet& particles, const double* sin_yaw,
                    const double* cos_yaw, std::size_t begin, std::size_t end, double* out) {
  std::size_t i = begin;
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && f.classes) i = scoreBlocksAvx2<true>(f, particles, sin_yaw, cos_yaw, begin, end, out);
  if (avx2 && !f.classes) {
    i = scoreBlocksAvx2<false>(f, particles, sin_yaw, cos_yaw, begin, end, out);
  }
#endif
  for (; i < end; ++i) {
    float px, py;
    particleInCells(f, particles, i, &px, &py);
    const float c = static_cast<float>(cos_yaw[i]);
    const float s = static_cast<float>(sin_yaw[i]);
    float sum = 0.0f;
    for (std::size_t b = 0; b < f.beams; ++b) {
      sum += endPointValue(f, px, py, c, s, f.bx[b], f.by[b]);
    }
    out[i] = sum;
  }
}

// The particle in the grid's frame, in cells, shifted by the one-cell
// border: what every per-beam loop over one particle starts from.
struct CellPose {
  float x, y, c, s;
};

CellPose cellPose(const ScoringFrame& f, const ParticleSet& particles, std::size_t i) {
  CellPose p;
  particleInCells(f, particles, i, &p.x, &p.y);
  const float yaw = static_cast<float>(particles.yaw[i] - f.origin.yaw);
  p.c = std::cos(yaw);
  p.s = std::sin(yaw);
  return p;
}

// For beam skipping: per beam, the number of particles whose end point lands
// in a cell of `near` (the same border and clamping as scoreParticles).
void countAgreeingParticles(const ScoringFrame& f, const uint8_t* near,
                            const ParticleSet& particles, std::vector<std::size_t>* counts) {
  counts->assign(f.beams, 0);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const CellPose p = cellPose(f, particles, i);
    for (std::size_t b = 0; b < f.beams; ++b) {
      (*counts)[b] += near[endPointCell(f, p.x, p.y, p.c, p.s, f.bx[b], f.by[b])];
    }
  }
}

// The frame for scoring `beams` end points (in cells) on `field`, whose
// classes' log-likelihoods `table` holds, or its cells' (`by_class` false;
// table nullptr: for endPointCell only).
ScoringFrame scoringFrame(const DistanceField& field, const float* table, bool by_class,
                          const float* bx, const float* by, std::size_t beams) {
  const OccupancyGrid& grid = field.grid();
  return ScoringFrame{table,
                      by_class ? field.classes() : nullptr,
                      static_cast<int>(field.classDistances().size()),
                      grid.width(),
                      grid.height(),
                      grid.width() + 2,
                      static_cast<float>(grid.width() + 1),
                      static_cast<float>(grid.height() + 1),
                      static_cast<float>(1.0 / grid.resolution()),
                      grid.origin(),
                      std::cos(grid.origin().yaw),
                      std::sin(grid.origin().yaw),
                      bx,
                      by,
                      beams};
}

}  // namespace

void LikelihoodFieldModel::score(const float* table, const float* bx, const float* by,
                                 std::size_t beams, const ParticleSet& particles,
                                 std::vector<double>* log_likelihood) const {
  const ScoringFrame frame = scoringFrame(*field_, table, !cellTables(), bx, by, beams);
  log_likelihood->resize(particles.size());
  // The headings' sines and cosines for the whole cloud at once (sinCos
  // vectorises), not one C library call per particle. Kept per thread: no
  // allocation per update. Only ever grown: the look-alike judge scores a
  // few poses on this thread between two scorings of the cloud, and a
  // vector shrunk to them was zero-filled back to the cloud's size (16 MB
  // for a million particles) on one thread before every scoring.
  const std::size_t n = particles.size();
  struct HeadingScratch {
    std::vector<double> heading, sin_yaw, cos_yaw;
  };
  HeadingScratch& heading_scratch = threadScratch<HeadingScratch>();
  std::vector<double>& heading = heading_scratch.heading;
  std::vector<double>& sin_yaw = heading_scratch.sin_yaw;
  std::vector<double>& cos_yaw = heading_scratch.cos_yaw;
  if (sin_yaw.size() < n) {
    sin_yaw.resize(n);
    cos_yaw.resize(n);
  }
  if (frame.origin.yaw != 0.0 && heading.size() < n) heading.resize(n);
  double* s = sin_yaw.data();
  double* c = cos_yaw.data();
  // One contiguous slice per thread; every particle's score is computed
  // alone, so the result is the same for any thread count.
  forEachSlice(n, params_.threads, [&](std::size_t begin, std::size_t end) {
    const double* yaw = particles.yaw.data();
    if (frame.origin.yaw != 0.0) {
      for (std::size_t i = begin; i < end; ++i) heading[i] = particles.yaw[i] - frame.origin.yaw;
      yaw = heading.data();
    }
    sinCos(yaw + begin, end - begin, s + begin, c + begin);
    scoreParticles(frame, particles, s, c, begin, end, log_likelihood->data());
  });
}

std::vector<uint8_t> LikelihoodFieldModel::keptBeams(const float* bx, const float* by,
                                                     std::size_t beams,
                                                     const ParticleSet& particles) const {
  const ScoringFrame frame = scoringFrame(*field_, nullptr, false, bx, by, beams);
  std::vector<std::size_t> agree;
  countAgreeingParticles(frame, near_.data(), particles, &agree);
  std::vector<uint8_t> kept(beams, 1);
  const double n = static_cast<double>(particles.size());
  std::size_t skipped = 0;
  for (std::size_t b = 0; b < beams; ++b) {
    // amcl keeps a beam when more than the threshold agree.
    if (!(static_cast<double>(agree[b]) / n > params_.beam_skip_threshold)) {
      kept[b] = 0;
      ++skipped;
    }
  }
  // Most beams disagreeing with the cloud means the cloud is wrong, not the
  // map: then every beam must count, or the filter could never notice.
  if (static_cast<double>(skipped) >=
      static_cast<double>(beams) * params_.beam_skip_error_threshold) {
    std::fill(kept.begin(), kept.end(), 1);
  }
  return kept;
}

std::size_t LikelihoodFieldModel::logLikelihoods(const PreparedScan& scan,
                                                 const ParticleSet& particles,
                                                 std::vector<double>* log_likelihood) const {
  const float* lookup = table(scan.range_max).data();
  const float inv_res = static_cast<float>(1.0 / field_->grid().resolution());
  // End points in cell units, so the inner loop needs no division.
  const std::size_t n = scan.size();
  std::vector<float> bx(n), by(n);
  for (std::size_t b = 0; b < n; ++b) {
    bx[b] = scan.x[b] * inv_res;
    by[b] = scan.y[b] * inv_res;
  }
  if (params_.beam_skip && particles.size() > 0 && n > 0) {
    // The skipped beams are left out of the list scored, so the per-beam
    // loop stays the same as without skipping.
    const std::vector<uint8_t> kept = keptBeams(bx.data(), by.data(), n, particles);
    std::size_t used = 0;
    for (std::size_t b = 0; b < n; ++b) {
      if (!kept[b]) continue;
      bx[used] = bx[b];
      by[used] = by[b];
      ++used;
    }
    score(lookup, bx.data(), by.data(), used, particles, log_likelihood);
    return used;
  }
  score(lookup, bx.data(), by.data(), n, particles, log_likelihood);
  return n;
}

}  // namespace pf

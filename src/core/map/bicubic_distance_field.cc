#include "pf_localization/core/map/bicubic_distance_field.h"

#include <cmath>
#include <cstdint>
#include <limits>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace pf {
namespace {

// Catmull-Rom weights of the four samples around t in [0, 1) (at -1, 0, 1,
// 2), and their derivatives with respect to t.
void cubicWeights(double t, double w[4], double dw[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = -0.5 * t3 + t2 - 0.5 * t;
  w[1] = 1.5 * t3 - 2.5 * t2 + 1.0;
  w[2] = -1.5 * t3 + 2.0 * t2 + 0.5 * t;
  w[3] = 0.5 * t3 - 0.5 * t2;
  dw[0] = -1.5 * t2 + 2.0 * t - 0.5;
  dw[1] = 4.5 * t2 - 5.0 * t;
  dw[2] = -4.5 * t2 + 4.0 * t + 0.5;
  dw[3] = 1.5 * t2 - t;
}

#if defined(__x86_64__)
// cubicWeights for four t at once, one per lane: the same operations in the
// same order, so the same bits.
__attribute__((target("avx2"))) inline void cubicWeights4(__m256d t, __m256d w[4], __m256d dw[4]) {
  const __m256d t2 = _mm256_mul_pd(t, t), t3 = _mm256_mul_pd(t2, t);
  const __m256d half = _mm256_set1_pd(0.5), one_half = _mm256_set1_pd(1.5);
  w[0] = _mm256_sub_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(-0.5), t3), t2),
                       _mm256_mul_pd(half, t));
  w[1] = _mm256_add_pd(
      _mm256_sub_pd(_mm256_mul_pd(one_half, t3), _mm256_mul_pd(_mm256_set1_pd(2.5), t2)),
      _mm256_set1_pd(1.0));
  w[2] = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(-1.5), t3),
                                     _mm256_mul_pd(_mm256_set1_pd(2.0), t2)),
                       _mm256_mul_pd(half, t));
  w[3] = _mm256_sub_pd(_mm256_mul_pd(half, t3), _mm256_mul_pd(half, t2));
  dw[0] = _mm256_sub_pd(
      _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(-1.5), t2), _mm256_mul_pd(_mm256_set1_pd(2.0), t)),
      half);
  dw[1] =
      _mm256_sub_pd(_mm256_mul_pd(_mm256_set1_pd(4.5), t2), _mm256_mul_pd(_mm256_set1_pd(5.0), t));
  dw[2] = _mm256_add_pd(
      _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(-4.5), t2), _mm256_mul_pd(_mm256_set1_pd(4.0), t)),
      half);
  dw[3] = _mm256_sub_pd(_mm256_mul_pd(one_half, t2), t);
}

// The clamped stencil indices lo - 1 .. lo + 2 (BicubicDistanceField::sample's
// clamp), four lanes at a time.
__attribute__((target("avx2"))) inline void stencil4(__m128i lo, int size, __m128i out[4]) {
  const __m128i zero = _mm_setzero_si128(), last = _mm_set1_epi32(size - 1);
  for (int i = 0; i < 4; ++i) {
    out[i] = _mm_min_epi32(_mm_max_epi32(_mm_add_epi32(lo, _mm_set1_epi32(i - 1)), zero), last);
  }
}

// What BicubicDistanceField::sample reads of its field.
struct Grid {
  double c, s, inv_res, origin_x, origin_y, max_distance;
  int width, height;
  const float* cells;       // DistanceField::surfaceCells, or nullptr: then
  const uint16_t* classes;  // DistanceField::classes
  const float* surface;     // and per class, its surface distance
};

// One row of four lanes' stencils: v[k] holds, in each lane, the surface
// distance of the cell at column xs[k] of the row starting at row_start.
// With a float a cell: `contiguous` (every lane's four columns are xs[0] ..
// xs[0] + 3, none clamped) fetches them with four loads and a transpose,
// faster than four gathers. Without: the cell's class (a four-byte gather
// at two-byte steps, the upper half masked off; classes() has an entry past
// the last cell), then the class's value.
__attribute__((target("avx2"))) inline void stencilRow4(const Grid& g, __m128i row_start,
                                                        const __m128i xs[4], bool contiguous,
                                                        __m256d v[4]) {
  if (!g.cells) {
    const __m128i low = _mm_set1_epi32(0xFFFF);
    for (int k = 0; k < 4; ++k) {
      const __m128i cell = _mm_add_epi32(row_start, xs[k]);
      const __m128i cls =
          _mm_and_si128(_mm_i32gather_epi32(reinterpret_cast<const int*>(g.classes), cell, 2), low);
      v[k] = _mm256_cvtps_pd(_mm_i32gather_ps(g.surface, cls, 4));
    }
    return;
  }
  if (!contiguous) {
    for (int k = 0; k < 4; ++k) {
      v[k] = _mm256_cvtps_pd(_mm_i32gather_ps(g.cells, _mm_add_epi32(row_start, xs[k]), 4));
    }
    return;
  }
  alignas(16) std::int32_t first[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(first), _mm_add_epi32(row_start, xs[0]));
  __m128 r0 = _mm_loadu_ps(g.cells + first[0]), r1 = _mm_loadu_ps(g.cells + first[1]);
  __m128 r2 = _mm_loadu_ps(g.cells + first[2]), r3 = _mm_loadu_ps(g.cells + first[3]);
  _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
  v[0] = _mm256_cvtps_pd(r0);
  v[1] = _mm256_cvtps_pd(r1);
  v[2] = _mm256_cvtps_pd(r2);
  v[3] = _mm256_cvtps_pd(r3);
}

// BicubicDistanceField::sample for the points [0, n) in blocks of four, one
// per AVX2 lane: every lane does the scalar operations in the same order (no
// fused multiply-add, the stencil summed row by row, each row cell by cell),
// so the samples are the same bits. A point off the map is computed at cell
// 0 and replaced, as the scalar code returns early. Returns the first point
// it did not sample.
__attribute__((target("avx2"))) std::size_t sampleBlocksAvx2(const Grid& g, const double* wx,
                                                             const double* wy, std::size_t n,
                                                             FieldSample* out) {
  const __m256d c = _mm256_set1_pd(g.c), s = _mm256_set1_pd(g.s), neg_s = _mm256_set1_pd(-g.s);
  const __m256d inv = _mm256_set1_pd(g.inv_res), half = _mm256_set1_pd(0.5);
  const __m256d below = _mm256_set1_pd(-2.0);
  const __m256d right = _mm256_set1_pd(g.width + 1.0), top = _mm256_set1_pd(g.height + 1.0);
  const __m128i width = _mm_set1_epi32(g.width);
  // Columns 1 .. width - 3: the stencil's four columns all on the map.
  const __m128i last_start = _mm_set1_epi32(g.width - 2);
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d ox = _mm256_sub_pd(_mm256_loadu_pd(wx + i), _mm256_set1_pd(g.origin_x));
    const __m256d oy = _mm256_sub_pd(_mm256_loadu_pd(wy + i), _mm256_set1_pd(g.origin_y));
    __m256d gx = _mm256_sub_pd(
        _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(c, ox), _mm256_mul_pd(s, oy)), inv), half);
    __m256d gy = _mm256_sub_pd(
        _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(neg_s, ox), _mm256_mul_pd(c, oy)), inv), half);
    // Ordered comparisons: false for NaN, as in the scalar test.
    const __m256d on = _mm256_and_pd(
        _mm256_and_pd(_mm256_cmp_pd(gx, below, _CMP_GT_OQ), _mm256_cmp_pd(gy, below, _CMP_GT_OQ)),
        _mm256_and_pd(_mm256_cmp_pd(gx, right, _CMP_LT_OQ), _mm256_cmp_pd(gy, top, _CMP_LT_OQ)));
    gx = _mm256_and_pd(gx, on);
    gy = _mm256_and_pd(gy, on);
    const __m128i ix = _mm256_cvttpd_epi32(_mm256_floor_pd(gx));
    const __m128i iy = _mm256_cvttpd_epi32(_mm256_floor_pd(gy));
    __m256d wxs[4], dwxs[4], wys[4], dwys[4];
    cubicWeights4(_mm256_sub_pd(gx, _mm256_cvtepi32_pd(ix)), wxs, dwxs);
    cubicWeights4(_mm256_sub_pd(gy, _mm256_cvtepi32_pd(iy)), wys, dwys);
    __m128i xs[4], ys[4];
    stencil4(ix, g.width, xs);
    stencil4(iy, g.height, ys);
    const bool contiguous =
        _mm_movemask_ps(_mm_castsi128_ps(_mm_and_si128(_mm_cmpgt_epi32(ix, _mm_setzero_si128()),
                                                       _mm_cmplt_epi32(ix, last_start)))) == 0xF;
    __m256d value = _mm256_setzero_pd(), dgx = value, dgy = value;
    for (int j = 0; j < 4; ++j) {
      __m256d v[4];
      stencilRow4(g, _mm_mullo_epi32(ys[j], width), xs, contiguous, v);
      __m256d row = _mm256_setzero_pd(), drow = row;
      for (int k = 0; k < 4; ++k) {
        row = _mm256_add_pd(row, _mm256_mul_pd(wxs[k], v[k]));
        drow = _mm256_add_pd(drow, _mm256_mul_pd(dwxs[k], v[k]));
      }
      value = _mm256_add_pd(value, _mm256_mul_pd(wys[j], row));
      dgx = _mm256_add_pd(dgx, _mm256_mul_pd(wys[j], drow));
      dgy = _mm256_add_pd(dgy, _mm256_mul_pd(dwys[j], row));
    }
    alignas(32) double distance[4], dx[4], dy[4];
    _mm256_store_pd(distance, _mm256_blendv_pd(_mm256_set1_pd(g.max_distance), value, on));
    _mm256_store_pd(
        dx,
        _mm256_and_pd(
            _mm256_mul_pd(_mm256_sub_pd(_mm256_mul_pd(c, dgx), _mm256_mul_pd(s, dgy)), inv), on));
    _mm256_store_pd(
        dy,
        _mm256_and_pd(
            _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(s, dgx), _mm256_mul_pd(c, dgy)), inv), on));
    for (int l = 0; l < 4; ++l) out[i + l] = {distance[l], dx[l], dy[l]};
  }
  return i;
}
#endif

}  // namespace

BicubicDistanceField::BicubicDistanceField(const DistanceField& field)
    : field_(field),
      cos_yaw_(std::cos(field.grid().origin().yaw)),
      sin_yaw_(std::sin(field.grid().origin().yaw)),
      inv_resolution_(1.0 / field.grid().resolution()),
      origin_x_(field.grid().origin().x),
      origin_y_(field.grid().origin().y),
      width_(field.grid().width()),
      height_(field.grid().height()),
      int_indices_(static_cast<std::int64_t>(width_) * height_ <=
                   std::numeric_limits<std::int32_t>::max()) {}

FieldSample BicubicDistanceField::sample(double wx, double wy) const {
  const double c = cos_yaw_, s = sin_yaw_, inv_res = inv_resolution_;
  const double ox = wx - origin_x_, oy = wy - origin_y_;
  // Continuous cell coordinates in which cell centres are integers.
  const double gx = (c * ox + s * oy) * inv_res - 0.5;
  const double gy = (-s * ox + c * oy) * inv_res - 0.5;
  // Well off the map (or NaN): nothing there, as in the likelihood field.
  if (!(gx > -2.0 && gy > -2.0 && gx < width_ + 1.0 && gy < height_ + 1.0)) {
    return {field_.maxDistance(), 0.0, 0.0};
  }
  const int ix = static_cast<int>(std::floor(gx)), iy = static_cast<int>(std::floor(gy));
  double wxs[4], dwxs[4], wys[4], dwys[4];
  cubicWeights(gx - ix, wxs, dwxs);
  cubicWeights(gy - iy, wys, dwys);
  // A stencil that reaches past the map's edge repeats the edge cells.
  // max_distance there instead would be a cliff next to a wall on the edge,
  // which the cubic overshoots into negative distances, making false minima.
  const auto clamp = [](int v, int size) { return v < 0 ? 0 : (v >= size ? size - 1 : v); };
  int xs[4];
  for (int i = 0; i < 4; ++i) xs[i] = clamp(ix - 1 + i, width_);
  double value = 0.0, dgx = 0.0, dgy = 0.0;
  for (int j = 0; j < 4; ++j) {
    const std::size_t row_start = static_cast<std::size_t>(clamp(iy - 1 + j, height_)) * width_;
    double row = 0.0, drow = 0.0;
    for (int i = 0; i < 4; ++i) {
      const double v = field_.surfaceDistance(row_start + xs[i]);
      row += wxs[i] * v;
      drow += dwxs[i] * v;
    }
    value += wys[j] * row;
    dgx += wys[j] * drow;
    dgy += dwys[j] * row;
  }
  // d/d(world) = R(origin yaw) d/d(cell) / resolution.
  return {value, (c * dgx - s * dgy) * inv_res, (s * dgx + c * dgy) * inv_res};
}

void BicubicDistanceField::sample(const double* wx, const double* wy, std::size_t n,
                                  FieldSample* out) const {
  std::size_t i = 0;
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2 && int_indices_) {
    const Grid g{cos_yaw_,
                 sin_yaw_,
                 inv_resolution_,
                 origin_x_,
                 origin_y_,
                 field_.maxDistance(),
                 width_,
                 height_,
                 field_.surfaceCells(),
                 field_.classes(),
                 field_.classSurfaceDistances().data()};
    i = sampleBlocksAvx2(g, wx, wy, n, out);
  }
#endif
  for (; i < n; ++i) out[i] = sample(wx[i], wy[i]);
}

}  // namespace pf

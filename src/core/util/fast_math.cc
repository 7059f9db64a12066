#include "pf_localization/core/util/fast_math.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "pf_localization/core/util/scratch_storage.h"

namespace pf {
namespace {

// fdlibm (k_sin.c, k_cos.c): minimax polynomials on [-pi/4, pi/4].
constexpr double kS1 = -1.66666666666666324348e-01, kS2 = 8.33333333332248946124e-03,
                 kS3 = -1.98412698298579493134e-04, kS4 = 2.75573137070700676789e-06,
                 kS5 = -2.50507602534068634195e-08, kS6 = 1.58969099521155010221e-10;
constexpr double kC1 = 4.16666666666666019037e-02, kC2 = -1.38888888888741095749e-03,
                 kC3 = 2.48015872894767294178e-05, kC4 = -2.75573143513906633035e-07,
                 kC5 = 2.08757232129817482790e-09, kC6 = -1.13596475577881948265e-11;
// pi/2 in three parts (fdlibm e_rem_pio2.c): k * kPio2_1 is exact for |k| < 2^20.
constexpr double kPio2_1 = 1.57079632673412561417e+00, kPio2_2 = 6.07710050630396597660e-11,
                 kPio2_3 = 2.02226624871116645580e-21;
constexpr double kTwoOverPi = 6.36619772367581382433e-01;
constexpr double kShifter = 6755399441055744.0;  // 1.5 * 2^52: adding it rounds to an integer
constexpr double kLimit = 1e5;

uint64_t toBits(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

double fromBits(uint64_t b) {
  double v;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

__attribute__((target_clones("avx2", "default"))) void sinCosKernel(const double* __restrict a,
                                                                    std::size_t n,
                                                                    double* __restrict s,
                                                                    double* __restrict c) {
  for (std::size_t i = 0; i < n; ++i) {
    const double x = a[i];
    // k = round(x * 2 / pi); its two low bits are the quadrant.
    const double shifted = x * kTwoOverPi + kShifter;
    const uint64_t q = toBits(shifted);
    const double k = shifted - kShifter;
    const double r = ((x - k * kPio2_1) - k * kPio2_2) - k * kPio2_3;
    const double z = r * r;
    const double sr = r + r * z * (kS1 + z * (kS2 + z * (kS3 + z * (kS4 + z * (kS5 + z * kS6)))));
    const double cr =
        1.0 - 0.5 * z + z * z * (kC1 + z * (kC2 + z * (kC3 + z * (kC4 + z * (kC5 + z * kC6)))));
    // Quadrant 1 and 3 swap sine and cosine; the sine is negative in
    // quadrants 2 and 3, the cosine in 1 and 2.
    const uint64_t swap = (q & 1) != 0 ? ~uint64_t{0} : 0;
    const uint64_t sb = (toBits(sr) & ~swap) | (toBits(cr) & swap);
    const uint64_t cb = (toBits(cr) & ~swap) | (toBits(sr) & swap);
    s[i] = fromBits(sb ^ ((q & 2) << 62));
    c[i] = fromBits(cb ^ (((q + 1) & 2) << 62));
  }
}

// fdlibm (e_exp.c).
constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10,
                 kInvLn2 = 1.44269504088896338700e+00;
constexpr double kP1 = 1.66666666666666019037e-01, kP2 = -2.77777777770155933842e-03,
                 kP3 = 6.61375632143793436117e-05, kP4 = -1.65339022054652515390e-06,
                 kP5 = 4.13813679705723846039e-08;

// expKernel's range: [-708, 709] by the approximation, and below -746,
// where exp rounds to zero (e^-746 is less than half the least subnormal).
constexpr double kExpKernelLow = -708.0, kExpKernelHigh = 709.0, kExpZeroBelow = -746.0;

__attribute__((target_clones("avx2", "default"))) void expKernel(const double* x, std::size_t n,
                                                                 double* out) {
  for (std::size_t i = 0; i < n; ++i) {
    // Within [-746, -708), above 709 and for NaN the result is wrong
    // here, and replaced by exps(); below -746 it is exp's, zero.
    const double v = x[i];
    // v = k ln2 + r, |r| <= ln2 / 2.
    const double k = (v * kInvLn2 + kShifter) - kShifter;
    const double hi = v - k * kLn2Hi;
    const double lo = k * kLn2Lo;
    const double r = hi - lo;
    const double t = r * r;
    const double c = r - t * (kP1 + t * (kP2 + t * (kP3 + t * (kP4 + t * kP5))));
    const double y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi);
    // 2^k in two factors, so that neither leaves the exponent's range (the
    // product may: subnormal, zero or infinite, as exp is). The biased
    // exponents are the low mantissa bits of e + 1023 + the shifter.
    const double k1 = (k * 0.5 + kShifter) - kShifter, k2 = k - k1;
    const double scale1 = fromBits(toBits(k1 + (1023.0 + kShifter)) << 52);
    const double scale2 = fromBits(toBits(k2 + (1023.0 + kShifter)) << 52);
    // Zero below kExpZeroBelow by a mask, not a branch: the loop vectorises.
    const uint64_t keep = v < kExpZeroBelow ? 0 : ~uint64_t{0};
    out[i] = fromBits(toBits(y * scale1 * scale2) & keep);
  }
}

// 1 when exp(v) is one that expKernel does not give (see there), else 0;
// comparisons combined as integers, not && and ||, so that loops over it
// vectorise.
inline unsigned needsLibraryExp(double v) {
  return static_cast<unsigned>(!(v < kExpZeroBelow)) &
         (static_cast<unsigned>(!(v >= kExpKernelLow)) |
          static_cast<unsigned>(!(v <= kExpKernelHigh)));
}

// Whether any of x[0, n) needsLibraryExp, or (sinCos) is beyond kLimit or
// NaN: one vectorised pass with no early exit, so that the common case
// (none) costs a compare per value, not a branch and a list.
__attribute__((target_clones("avx2", "default"))) bool anyNeedsLibraryExp(const double* x,
                                                                          std::size_t n) {
  unsigned any = 0;
  for (std::size_t i = 0; i < n; ++i) any |= needsLibraryExp(x[i]);
  return any != 0;
}
__attribute__((target_clones("avx2", "default"))) bool anyBeyondLimit(const double* x,
                                                                      std::size_t n) {
  unsigned any = 0;
  for (std::size_t i = 0; i < n; ++i) any |= std::fabs(x[i]) <= kLimit ? 0 : 1;
  return any != 0;
}

}  // namespace

void exps(const double* x, std::size_t n, double* out) {
  if (!anyNeedsLibraryExp(x, n)) {
    expKernel(x, n, out);
    return;
  }
  // Saved first: out may be x.
  struct Scratch {
    std::vector<std::size_t> outside;
    std::vector<double> saved;
  };
  Scratch& scratch = threadScratch<Scratch>();
  std::vector<std::size_t>& outside = scratch.outside;
  std::vector<double>& saved = scratch.saved;
  outside.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (needsLibraryExp(x[i])) outside.push_back(i);
  }
  saved.clear();
  for (std::size_t i : outside) saved.push_back(x[i]);
  expKernel(x, n, out);
  for (std::size_t j = 0; j < outside.size(); ++j) out[outside[j]] = std::exp(saved[j]);
}

void sinCos(const double* angle, std::size_t n, double* s, double* c) {
  sinCosKernel(angle, n, s, c);
  if (!anyBeyondLimit(angle, n)) return;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(std::fabs(angle[i]) <= kLimit)) {
      s[i] = std::sin(angle[i]);
      c[i] = std::cos(angle[i]);
    }
  }
}

}  // namespace pf

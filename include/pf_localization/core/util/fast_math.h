// Sine, cosine and exponential of a whole array at once, for the per-particle loops of the
// filter update (motion sampling, scoring, the estimate's mean heading), and
// an atan2 for per-point loops (fastAtan2).
//
// The C library computes one angle per call; over thousands of particles per
// update that call was a tenth of the update. sinCos() evaluates the same
// functions with branch-free polynomials (fdlibm's kernels on [-pi/4, pi/4]
// after a Cody-Waite reduction by pi/2), which the compiler vectorises; the
// result is within 2 ulp of the exact values for |angle| <= 1e5 (larger or
// non-finite angles fall back on std::sin and std::cos). The portable and
// the AVX2 builds give the same bits: no fused multiply-add is used.
#pragma once

#include <cmath>
#include <cstddef>

namespace pf {

/// s[i] = sin(angle[i]), c[i] = cos(angle[i]) for i < n. The arrays may not overlap.
void sinCos(const double* angle, std::size_t n, double* s, double* c);

/// out[i] = exp(x[i]) for i < n (out may be x), within 1 ulp, by fdlibm's
/// rational approximation, branch free so that it vectorises: the weighting
/// step takes an exponential per particle, twice per update. Below -745 it
/// gives 0, above 709.8 infinity; NaN stays NaN.
void exps(const double* x, std::size_t n, double* out);

// atan2 for per-point loops that need an angle to a few microradians, not to
// the last bit: binning a 30 000-point cloud by bearing (cloud_scan_reducer.h).
//
// fastAtan2() reduces to the first octant (|y/x| <= 1, one division), evaluates
// Abramowitz & Stegun's polynomial 4.4.49 there (|error| <= 2e-8 rad), and
// unfolds the octant with selects rather than branches, so that a loop of
// it vectorises.
/// atan2(y, x) in [-pi, pi] within 1e-7 rad for finite y and x, not both
/// zero; +-0 for (+-0, +-0). Not for NaN or infinite arguments (the result is
/// then unspecified): callers drop those points first.
inline double fastAtan2(double y, double x) {
  const double ax = std::fabs(x), ay = std::fabs(y);
  const bool steep = ay > ax;
  const double num = steep ? ax : ay;
  const double den = steep ? ay : ax;
  const double t = den > 0.0 ? num / den : 0.0;  // in [0, 1]
  const double s = t * t;
  // A&S 4.4.49: atan(t) / t = 1 + a2 t^2 + ... + a16 t^16 on [0, 1].
  double p = 0.0028662257;
  p = p * s - 0.0161657367;
  p = p * s + 0.0429096138;
  p = p * s - 0.0752896400;
  p = p * s + 0.1065626393;
  p = p * s - 0.1420889944;
  p = p * s + 0.1999355085;
  p = p * s - 0.3333314528;
  p = p * s + 1.0;
  double a = p * t;                 // atan of the first octant's angle
  a = steep ? M_PI_2 - a : a;       // |y| > |x|: measured from the y axis
  a = x < 0.0 ? M_PI - a : a;       // left half plane
  return std::signbit(y) ? -a : a;  // lower half plane (and -0 as atan2 does)
}

}  // namespace pf

// Sine, cosine and exponential of a whole array at once, for the per-particle loops of the
// filter update (motion sampling, scoring, the estimate's mean heading).
//
// The C library computes one angle per call; over thousands of particles per
// update that call was a tenth of the update. sinCos() evaluates the same
// functions with branch-free polynomials (fdlibm's kernels on [-pi/4, pi/4]
// after a Cody-Waite reduction by pi/2), which the compiler vectorises; the
// result is within 2 ulp of the exact values for |angle| <= 1e5 (larger or
// non-finite angles fall back on std::sin and std::cos). The portable and
// the AVX2 builds give the same bits: no fused multiply-add is used.
#pragma once

#include <cstddef>

namespace pf {

/// s[i] = sin(angle[i]), c[i] = cos(angle[i]) for i < n. The arrays may not overlap.
void sinCos(const double* angle, std::size_t n, double* s, double* c);

/// out[i] = exp(x[i]) for i < n (out may be x), within 1 ulp, by fdlibm's
/// rational approximation, branch free so that it vectorises: the weighting
/// step takes an exponential per particle, twice per update. Below -745 it
/// gives 0, above 709.8 infinity; NaN stays NaN.
void exps(const double* x, std::size_t n, double* out);

}  // namespace pf

// How cautiously a scan's evidence is weighed: the ESS fraction that
// applyLikelihood (weighting.h) tempers the likelihood to keep.
//
// A filter that is not sure of itself weighs evidence more cautiously
// (tempering_ess_fraction_uncertain): rival hypotheses (twin rooms) then
// survive until the scans really separate them, instead of the luckiest one
// winning outright. Not when the one thing wrong is a wide cloud whose beams
// fit (uncertain, no rival, the beams fitting as well as when localized):
// caution would only keep the cloud wide, and the estimate, its mean, off.
// Raising a likelihood to a power below 1 is the idea of annealed importance
// sampling (Neal, Statistics and Computing 11, 2001). See docs/design.md,
// "Tempering follows the last verdict".
#pragma once

#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/filter/particle_filter_params.h"

namespace pf {

/// tempering_ess_fraction while the last update's scan said "localized", or
/// "uncertain" only by the cloud's spread; tempering_ess_fraction_uncertain
/// otherwise. `fit_state` is that scan's verdict before holdAfterJump,
/// `last` the confidence it gave (rivals, hit fraction).
double temperingEssFraction(LocalizationState fit_state, const Confidence& last,
                            const ParticleFilterParams& params);

}  // namespace pf

#include "pf_localization/core/filter/tempering.h"

namespace pf {

double temperingEssFraction(LocalizationState fit_state, const Confidence& last,
                            const ParticleFilterParams& params) {
  const bool spread_only = fit_state == LocalizationState::kUncertain && last.rivals == 0 &&
                           last.hit_fraction >= params.confidence.localized_hit_fraction;
  return fit_state == LocalizationState::kLocalized || spread_only
             ? params.tempering_ess_fraction
             : params.tempering_ess_fraction_uncertain;
}

}  // namespace pf

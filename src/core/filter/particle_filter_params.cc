#include "pf_localization/core/filter/particle_filter_params.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "pf_localization/core/util/parameter_table.h"

namespace pf {
namespace {

bool finite(double v) { return std::isfinite(v); }

const char* laserModelName(LaserModelType type) {
  switch (type) {
    case LaserModelType::kLikelihoodFieldProb:
      return "likelihood_field_prob";
    case LaserModelType::kBeam:
      return "beam";
    case LaserModelType::kLikelihoodField:
      break;
  }
  return "likelihood_field";
}

const ParamInfo& laserModelInfo() {
  static const ParamInfo info =
      ParamInfo("laser_model_type", "",
                "likelihood_field; likelihood_field_prob (with beam skipping when do_beamskip); "
                "beam (ranges ray cast on the map)")
          .oneOf({"likelihood_field", "likelihood_field_prob", "beam"})
          .amcl();
  return info;
}

void setLaserModel(ParticleFilterParams& p, const std::string& word) {
  checkValue(laserModelInfo(), word);
  p.laser_model_type = word == "beam"                    ? LaserModelType::kBeam
                       : word == "likelihood_field_prob" ? LaserModelType::kLikelihoodFieldProb
                                                         : LaserModelType::kLikelihoodField;
}

// ParticleFilterParams' own members, by the group each is listed under.
ParameterTable<ParticleFilterParams> updateParameters() {
  using P = ParticleFilterParams;
  using I = ParamInfo;
  return {
      member(&P::update_min_d, I("update_min_d", "m", "translation that triggers a filter update")
                                   .in(Range::atLeast(0))
                                   .amcl()
                                   .live(0, 5)),
      member(&P::update_min_a, I("update_min_a", "rad", "rotation that triggers a filter update")
                                   .in(Range::atLeast(0))
                                   .amcl()
                                   .live(0, 6.2832))};
}

ParameterTable<ParticleFilterParams> laserModelParameters() {
  return {computed<ParticleFilterParams, std::string>(
      [](const ParticleFilterParams& p) { return laserModelName(p.laser_model_type); },
      setLaserModel, laserModelInfo())};
}

ParameterTable<ParticleFilterParams> computeParameters() {
  return {member(
      &ParticleFilterParams::threads,
      ParamInfo("threads", "threads", "threads of the filter update; the same result for any")
          .in(Range::atLeast(0))
          .withNote("0: one per processor core"))};
}

ParameterTable<ParticleFilterParams> refinementParameters() {
  return {member(
      &ParticleFilterParams::refine_estimate,
      ParamInfo("refine_estimate", "", "publish the pose fitted to the map by the scan").live())};
}

// All of them, for the check.
const ParameterTable<ParticleFilterParams>& ownParameters() {
  static const ParameterTable<ParticleFilterParams> table = [] {
    ParameterTable<ParticleFilterParams> t = updateParameters();
    append(&t, laserModelParameters(), "sensor");
    append(&t, refinementParameters(), "refinement");
    append(&t, computeParameters(), "compute");
    return t;
  }();
  return table;
}

// Checks of the options that are the filter's own constants, not parameters
// (a programmer who sets them gets the same kind of message).
void validateInternals(const ParticleFilterParams& p) {
  requireParameter(p.kld.bin_xy >= 1e-3 && finite(p.kld.bin_xy), "KldParams::bin_xy", ">= 0.001",
                   p.kld.bin_xy);
  requireParameter(p.kld.bin_yaw >= 1e-3 && finite(p.kld.bin_yaw), "KldParams::bin_yaw", ">= 0.001",
                   p.kld.bin_yaw);
  requireParameter(p.odom_jump_limit > 0.0, "ParticleFilterParams::odom_jump_limit", "> 0",
                   p.odom_jump_limit);
  requireParameter(p.update_fit_drop >= 0.0 && p.update_fit_drop <= 1.0,
                   "ParticleFilterParams::update_fit_drop", "in [0, 1]", p.update_fit_drop);
  requireParameter(p.update_fit_distance > 0.0 && finite(p.update_fit_distance),
                   "ParticleFilterParams::update_fit_distance", "> 0", p.update_fit_distance);
  requireParameter(p.resample_ess_fraction > 0.0 && p.resample_ess_fraction <= 1.0,
                   "ParticleFilterParams::resample_ess_fraction", "in (0, 1]",
                   p.resample_ess_fraction);
  requireParameter(p.tempering_ess_fraction >= 0.0 && p.tempering_ess_fraction <= 1.0,
                   "ParticleFilterParams::tempering_ess_fraction", "in [0, 1]",
                   p.tempering_ess_fraction);
  requireParameter(
      p.tempering_ess_fraction_uncertain >= 0.0 && p.tempering_ess_fraction_uncertain <= 1.0,
      "ParticleFilterParams::tempering_ess_fraction_uncertain", "in [0, 1]",
      p.tempering_ess_fraction_uncertain);
  requireParameter(p.clusters.cell_xy > 0.0 && finite(p.clusters.cell_xy), "ClusterParams::cell_xy",
                   "> 0", p.clusters.cell_xy);
  requireParameter(p.clusters.cell_yaw > 0.0 && finite(p.clusters.cell_yaw),
                   "ClusterParams::cell_yaw", "> 0", p.clusters.cell_yaw);
  requireParameter(p.clusters.join_weight_ratio >= 0.0 && p.clusters.join_weight_ratio <= 1.0,
                   "ClusterParams::join_weight_ratio", "in [0, 1]", p.clusters.join_weight_ratio);
  validateInternals(p.recovery);
  validate(p.confidence);
  validate(p.refiner);
}

}  // namespace

const ParameterTable<RecoveryParams>& recoveryParameters() {
  using P = RecoveryParams;
  using I = ParamInfo;
  static const ParameterTable<P> table = {
      member(&P::alpha_slow,
             I("recovery_alpha_slow", "1/update", "long-term average rate of the scan fit")
                 .in(Range::closed(0, 1))
                 .withNote(
                     "0: no injection on a falling fit; a cloud that turns lost is still searched")
                 .amcl()
                 .live(0, 1)),
      member(&P::alpha_fast,
             I("recovery_alpha_fast", "1/update", "short-term average rate of the scan fit")
                 .in(Range::closed(0, 1))
                 .amcl()
                 .live(0, 1)),
  };
  return table;
}

void validateInternals(const RecoveryParams& r) {
  requireParameter(r.trigger_ratio > 0.0 && r.trigger_ratio <= 1.0, "RecoveryParams::trigger_ratio",
                   "in (0, 1]", r.trigger_ratio);
  requireParameter(r.kidnap_prior > 0.0 && r.kidnap_prior <= 1.0, "RecoveryParams::kidnap_prior",
                   "in (0, 1]", r.kidnap_prior);
  requireParameter(r.patience >= 0, "RecoveryParams::patience", ">= 0", r.patience);
  requireParameter(r.patience_localized >= r.patience, "RecoveryParams::patience_localized",
                   ">= patience", r.patience_localized);
  requireParameter(r.lost_share >= 0.0 && r.lost_share < 1.0, "RecoveryParams::lost_share",
                   "in [0, 1)", r.lost_share);
  requireParameter(r.expansion_ratio >= 0.0 && r.expansion_ratio < 1.0,
                   "RecoveryParams::expansion_ratio", "in [0, 1)", r.expansion_ratio);
  requireParameter(r.expansion_std_xy >= 0.0 && finite(r.expansion_std_xy),
                   "RecoveryParams::expansion_std_xy", ">= 0", r.expansion_std_xy);
  requireParameter(r.expansion_std_yaw >= 0.0 && finite(r.expansion_std_yaw),
                   "RecoveryParams::expansion_std_yaw", ">= 0", r.expansion_std_yaw);
}

const ParameterTable<ParticleFilterParams>& particleFilterParameters() {
  using P = ParticleFilterParams;
  static const ParameterTable<P> table = [] {
    ParameterTable<P> t;
    append(&t, nested(&P::kld, kldParameters()), "particles");
    append(&t, updateParameters(), "updates");
    append(&t, nested(&P::recovery, recoveryParameters()), "recovery");
    append(&t, nested(&P::motion, odometryMotionParameters()), "motion");
    append(&t, laserModelParameters(), "sensor");
    append(&t, nested(&P::sensor, likelihoodFieldParameters()), "sensor");
    append(&t, nested(&P::sensor, beamSkipParameters()), "sensor");
    append(&t, nested(&P::beam, beamModelParameters()), "sensor");
    append(&t, refinementParameters(), "refinement");
    append(&t, computeParameters(), "compute");
    return t;
  }();
  return table;
}

int resolvedThreads(int threads) {
  if (threads > 0) return threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void validate(const ParticleFilterParams& p) {
  checkRanges(kldParameters(), p.kld);
  // A wrong sign is said as such first (max_particles = -5 must be >= 1),
  // then how the two bounds relate.
  requireParameter(p.kld.max_particles >= p.kld.min_particles, "max_particles",
                   ">= min_particles (" + std::to_string(p.kld.min_particles) + ")",
                   p.kld.max_particles);
  checkRanges(ownParameters(), p);
  checkRanges(recoveryParameters(), p.recovery);
  requireParameter(p.recovery.alpha_slow == 0.0 || p.recovery.alpha_fast > p.recovery.alpha_slow,
                   "recovery_alpha_fast", "> recovery_alpha_slow when recovery is on",
                   p.recovery.alpha_fast);
  validate(p.motion);
  validate(p.sensor);
  checkRanges(beamModelParameters(), p.beam);
  validateInternals(p);
}

}  // namespace pf

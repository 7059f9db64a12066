#include "pf_localization/core/particle_filter_params.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pf_localization/core/parameter_check.h"

namespace pf {
namespace {

bool finite(double v) { return std::isfinite(v); }

}  // namespace

void validate(const ParticleFilterParams& p) {
  requireParameter(p.kld.min_particles >= 1, "min_particles", ">= 1", p.kld.min_particles);
  requireParameter(p.kld.max_particles >= p.kld.min_particles, "max_particles",
                   ">= min_particles (" + std::to_string(p.kld.min_particles) + ")",
                   p.kld.max_particles);
  requireParameter(p.kld.kld_err > 0.0 && finite(p.kld.kld_err), "kld_err", "> 0", p.kld.kld_err);
  requireParameter(p.kld.confidence > 0.0 && p.kld.confidence < 1.0, "kld_confidence", "in (0, 1)",
                   p.kld.confidence);
  requireParameter(p.kld.bin_xy >= 1e-3 && finite(p.kld.bin_xy), "kld_bin_xy", ">= 0.001",
                   p.kld.bin_xy);
  requireParameter(p.kld.bin_yaw >= 1e-3 && finite(p.kld.bin_yaw), "kld_bin_yaw", ">= 0.001",
                   p.kld.bin_yaw);
  requireParameter(p.odom_jump_limit > 0.0, "odom_jump_limit", "> 0", p.odom_jump_limit);
  requireParameter(p.update_min_d >= 0.0 && finite(p.update_min_d), "update_min_d", ">= 0",
                   p.update_min_d);
  requireParameter(p.update_min_a >= 0.0 && finite(p.update_min_a), "update_min_a", ">= 0",
                   p.update_min_a);
  requireParameter(p.update_fit_drop >= 0.0 && p.update_fit_drop <= 1.0, "update_fit_drop",
                   "in [0, 1]", p.update_fit_drop);
  requireParameter(p.update_fit_distance > 0.0 && finite(p.update_fit_distance),
                   "update_fit_distance", "> 0", p.update_fit_distance);
  requireParameter(p.resample_ess_fraction > 0.0 && p.resample_ess_fraction <= 1.0,
                   "resample_ess_fraction", "in (0, 1]", p.resample_ess_fraction);
  requireParameter(p.tempering_ess_fraction >= 0.0 && p.tempering_ess_fraction <= 1.0,
                   "tempering_ess_fraction", "in [0, 1]", p.tempering_ess_fraction);
  requireParameter(
      p.tempering_ess_fraction_uncertain >= 0.0 && p.tempering_ess_fraction_uncertain <= 1.0,
      "tempering_ess_fraction_uncertain", "in [0, 1]", p.tempering_ess_fraction_uncertain);
  requireParameter(p.clusters.cell_xy > 0.0 && finite(p.clusters.cell_xy), "cluster_xy", "> 0",
                   p.clusters.cell_xy);
  requireParameter(p.clusters.cell_yaw > 0.0 && finite(p.clusters.cell_yaw), "cluster_yaw", "> 0",
                   p.clusters.cell_yaw);
  requireParameter(p.clusters.join_weight_ratio >= 0.0 && p.clusters.join_weight_ratio <= 1.0,
                   "cluster_join_weight_ratio", "in [0, 1]", p.clusters.join_weight_ratio);
  requireParameter(p.recovery.alpha_slow >= 0.0 && p.recovery.alpha_slow <= 1.0,
                   "recovery_alpha_slow", "in [0, 1]", p.recovery.alpha_slow);
  requireParameter(p.recovery.alpha_fast >= 0.0 && p.recovery.alpha_fast <= 1.0,
                   "recovery_alpha_fast", "in [0, 1]", p.recovery.alpha_fast);
  requireParameter(p.recovery.trigger_ratio > 0.0 && p.recovery.trigger_ratio <= 1.0,
                   "recovery_trigger_ratio", "in (0, 1]", p.recovery.trigger_ratio);
  requireParameter(p.recovery.kidnap_prior > 0.0 && p.recovery.kidnap_prior <= 1.0,
                   "recovery_kidnap_prior", "in (0, 1]", p.recovery.kidnap_prior);
  requireParameter(p.recovery.patience >= 0, "recovery_patience", ">= 0", p.recovery.patience);
  requireParameter(p.recovery.patience_localized >= p.recovery.patience,
                   "recovery_patience_localized", ">= recovery_patience",
                   p.recovery.patience_localized);
  requireParameter(p.recovery.lost_share >= 0.0 && p.recovery.lost_share < 1.0,
                   "recovery_lost_share", "in [0, 1)", p.recovery.lost_share);
  requireParameter(p.recovery.expansion_ratio >= 0.0 && p.recovery.expansion_ratio < 1.0,
                   "recovery_expansion_ratio", "in [0, 1)", p.recovery.expansion_ratio);
  requireParameter(p.recovery.expansion_std_xy >= 0.0 && finite(p.recovery.expansion_std_xy),
                   "recovery_expansion_std_xy", ">= 0", p.recovery.expansion_std_xy);
  requireParameter(p.recovery.expansion_std_yaw >= 0.0 && finite(p.recovery.expansion_std_yaw),
                   "recovery_expansion_std_yaw", ">= 0", p.recovery.expansion_std_yaw);
  requireParameter(p.recovery.alpha_slow == 0.0 || p.recovery.alpha_fast > p.recovery.alpha_slow,
                   "recovery_alpha_fast", "> recovery_alpha_slow when recovery is on",
                   p.recovery.alpha_fast);
  validate(p.confidence);
  validate(p.refiner);
  const auto& s = p.sensor;
  requireParameter(s.z_hit >= 0.0 && finite(s.z_hit), "laser_z_hit", ">= 0", s.z_hit);
  requireParameter(s.z_rand >= 0.0 && finite(s.z_rand), "laser_z_rand", ">= 0", s.z_rand);
  requireParameter(s.z_hit + s.z_rand > 0.0, "laser_z_hit + laser_z_rand", "> 0",
                   s.z_hit + s.z_rand);
  requireParameter(s.sigma_hit > 0.0 && finite(s.sigma_hit), "laser_sigma_hit", "> 0", s.sigma_hit);
  requireParameter(s.max_distance > 0.0 && finite(s.max_distance), "laser_likelihood_max_dist",
                   "> 0", s.max_distance);
  requireParameter(s.max_beams >= 1, "laser_max_beams", ">= 1", s.max_beams);
  requireParameter(s.likelihood_exponent > 0.0 && s.likelihood_exponent <= 1.0,
                   "laser_likelihood_exponent", "in (0, 1]", s.likelihood_exponent);
  requireParameter(s.range_min >= 0.0 && finite(s.range_min), "laser_min_range", ">= 0",
                   s.range_min);
  requireParameter(s.range_max >= 0.0 && finite(s.range_max), "laser_max_range", ">= 0",
                   s.range_max);
  if (p.laser_model_type == LaserModelType::kBeam) {
    requireParameter(p.beam.z_short >= 0.0 && finite(p.beam.z_short), "laser_z_short", ">= 0",
                     p.beam.z_short);
    requireParameter(p.beam.z_max >= 0.0 && finite(p.beam.z_max), "laser_z_max", ">= 0",
                     p.beam.z_max);
    requireParameter(p.beam.lambda_short > 0.0 && finite(p.beam.lambda_short), "laser_lambda_short",
                     "> 0", p.beam.lambda_short);
  }
  validateBeamSkip(s);
  const auto& m = p.motion;
  const double alphas[] = {m.alpha1, m.alpha2, m.alpha3, m.alpha4, m.alpha5};
  for (int i = 0; i < 5; ++i) {
    requireParameter(alphas[i] >= 0.0 && finite(alphas[i]), "odom_alpha" + std::to_string(i + 1),
                     ">= 0", alphas[i]);
  }
  requireParameter(m.fault_fraction >= 0.0 && m.fault_fraction < 1.0, "odom_fault_fraction",
                   "in [0, 1)", m.fault_fraction);
  requireParameter(m.fault_fraction_max >= m.fault_fraction && m.fault_fraction_max < 1.0,
                   "odom_fault_fraction_max", "in [odom_fault_fraction, 1)", m.fault_fraction_max);
  requireParameter(m.fault_suspect_fraction > 0.0, "odom_fault_suspect_fraction", "> 0",
                   m.fault_suspect_fraction);
  requireParameter(m.fault_margin >= 0.0 && finite(m.fault_margin), "odom_fault_margin", ">= 0",
                   m.fault_margin);
}

}  // namespace pf

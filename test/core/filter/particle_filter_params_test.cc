// ParticleFilterParams: the defaults are valid, and every invalid value is
// refused, by validate() and by the filter's constructor, with a message that
// names the parameter and its valid range.
#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>
#include <string>

#include "core/filter/particle_filter_world.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "support/exception_message.h"

namespace pf {
namespace {

using filter_world::baseParams;

// The message of the std::invalid_argument `f` throws ("" for none).
std::string whatOf(const std::function<void()>& f) {
  return test::whatOf<std::invalid_argument>(f);
}

// --- Parameters ----------------------------------------------------------------

void expectInvalid(const std::function<void(ParticleFilterParams&)>& change,
                   const std::string& name) {
  ParticleFilterParams p = baseParams();
  change(p);
  const std::string what = whatOf([&] { validate(p); });
  EXPECT_NE(std::string::npos, what.find(name))
      << "expected an error naming " << name << ", got \"" << what << "\"";
  EXPECT_FALSE(whatOf([&] { ParticleFilter filter(p); }).empty());
}

TEST(ParticleFilterParams, DefaultsAreValid) {
  EXPECT_NO_THROW(validate(ParticleFilterParams()));
  EXPECT_NO_THROW(validate(baseParams()));
}

TEST(ParticleFilterParams, InvalidValuesAreNamed) {
  using P = ParticleFilterParams;
  expectInvalid([](P& p) { p.kld.min_particles = -5; }, "min_particles");
  expectInvalid([](P& p) { p.kld.min_particles = 0; }, "min_particles");
  expectInvalid([](P& p) { p.kld.max_particles = -1; }, "max_particles");
  expectInvalid([](P& p) { p.kld.max_particles = 299; }, "max_particles");  // < min 300
  expectInvalid([](P& p) { p.sensor.sigma_hit = 0.0; }, "laser_sigma_hit");
  expectInvalid([](P& p) { p.sensor.sigma_hit = -0.2; }, "laser_sigma_hit");
  expectInvalid([](P& p) { p.motion.alpha1 = -0.1; }, "odom_alpha1");
  expectInvalid([](P& p) { p.motion.alpha3 = -1e-9; }, "odom_alpha3");
  expectInvalid([](P& p) { p.motion.alpha5 = NAN; }, "odom_alpha5");
  expectInvalid([](P& p) { p.sensor.z_hit = p.sensor.z_rand = 0.0; }, "laser_z_hit + laser_z_rand");
  expectInvalid([](P& p) { p.sensor.z_rand = -0.5; }, "laser_z_rand");
  expectInvalid([](P& p) { p.kld.confidence = 0.0; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.confidence = 1.0; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.confidence = 1.5; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.confidence = NAN; }, "kld_confidence");
  expectInvalid([](P& p) { p.kld.kld_err = 0.0; }, "kld_err");
  expectInvalid([](P& p) { p.resample_ess_fraction = 0.0; },
                "ParticleFilterParams::resample_ess_fraction");
  expectInvalid([](P& p) { p.resample_ess_fraction = 1.5; },
                "ParticleFilterParams::resample_ess_fraction");
  expectInvalid([](P& p) { p.update_min_d = -0.1; }, "update_min_d");
  expectInvalid([](P& p) { p.threads = -1; }, "threads");
  expectInvalid([](P& p) { p.sensor.max_beams = 0; }, "laser_max_beams");
  expectInvalid([](P& p) { p.sensor.max_distance = 0.0; }, "laser_likelihood_max_dist");
  expectInvalid([](P& p) { p.clusters.cell_xy = 0.0; }, "ClusterParams::cell_xy");
  expectInvalid([](P& p) { p.recovery.alpha_slow = 0.1, p.recovery.alpha_fast = 0.05; },
                "recovery_alpha_fast");
  // The message names the valid range too.
  ParticleFilterParams p = baseParams();
  p.kld.confidence = 2.0;
  EXPECT_NE(std::string::npos, whatOf([&] { validate(p); }).find("(0, 1)"));
}

TEST(ParticleFilterParams, SensorModelParametersAreNamed) {
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.laser_model_type = LaserModelType::kBeam;
        p.beam.lambda_short = 0.0;
      },
      "laser_lambda_short");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.laser_model_type = LaserModelType::kBeam;
        p.beam.z_short = -0.1;
      },
      "laser_z_short");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.laser_model_type = LaserModelType::kBeam;
        p.beam.z_max = NAN;
      },
      "laser_z_max");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.sensor.beam_skip = true;
        p.sensor.beam_skip_distance = 0.0;
      },
      "beam_skip_distance");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.sensor.beam_skip = true;
        p.sensor.beam_skip_threshold = 1.5;
      },
      "beam_skip_threshold");
  expectInvalid(
      [](ParticleFilterParams& p) {
        p.sensor.beam_skip = true;
        p.sensor.beam_skip_error_threshold = -0.1;
      },
      "beam_skip_error_threshold");
}

}  // namespace
}  // namespace pf

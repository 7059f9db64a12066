// Odometry motion model: moves every particle by the motion the wheel odometry
// reports, with noise that grows with the motion.
//
// Differential drive: "sample_motion_model_odometry" of Thrun, Burgard & Fox,
// "Probabilistic Robotics" (2005), table 5.6. The step is split into a
// rotation rot1 towards the direction of travel, a translation trans and a
// final rotation rot2, each perturbed with a standard deviation of
//   rot:   sqrt(alpha1 * rot^2 + alpha2 * trans^2)
//   trans: sqrt(alpha3 * trans^2 + alpha4 * (rot1^2 + rot2^2))
// except that driving backwards (rot1 near pi) counts as min(|rot1|,
// |pi - rot1|) of rotation, and rot1 is 0 for tiny translations.
// Omnidirectional (amcl's omni convention): a translation (forward, strafe)
// plus a rotation,
//   trans:  sqrt(alpha3 * trans^2 + alpha1 * rot^2)
//   rot:    sqrt(alpha4 * rot^2 + alpha2 * trans^2)
//   strafe: sqrt(alpha1 * rot^2 + alpha5 * trans^2)
//
// The alphas describe one filter update's step, as in amcl: a longer step
// stands for several updates, its variance linear in its length (each v^2
// above becomes v * min(v, one update's v)).
//
// Odometry faults: a mixture of a reliable and an unreliable component
// (Thrun, Burgard & Fox, section 6.3.1, applied to motion). A share of the
// particles (fault_fraction .. fault_fraction_max, set per step by
// OdometryFaultTracker) takes, half of them, the reversed translation and,
// the other half, no translation (uniform within +-fault_margin); the scans
// decide which were right. Why: docs/design.md, "A long step's noise" and
// "Odometry faults are observed, not assumed".
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/util/parameter_table.h"
#include "pf_localization/core/util/pose2.h"
#include "pf_localization/core/util/random.h"

namespace pf {

struct OdometryMotionParams {
  enum class Kind { kDifferential, kOmni };
  Kind kind = Kind::kDifferential;
  double alpha1 = 0.2;  // rotation noise from rotation      (rad^2/rad^2)
  double alpha2 = 0.2;  // rotation noise from translation   (rad^2/m^2)
  double alpha3 = 0.2;  // translation noise from translation (m^2/m^2)
  double alpha4 = 0.2;  // translation noise from rotation   (m^2/rad^2)
  double alpha5 = 0.2;  // strafe noise from translation, omni only (m^2/m^2)
  // Share of the particles that assume the odometry's translation was wrong
  // this step (see above). 0 is the textbook model. Enough that a
  // reversal's first update finds a few reversed particles near the truth
  // in a cloud of a thousand: with 0.01 (five reversed ones) fr079's
  // reversals went 0.50 +- 0.02 m off before the share could rise; with
  // 0.03, 0.41-0.46 m. [0, 1)
  double fault_fraction = 0.03;
  // The filter raises the share up to this while the faulty particles win
  // the weight (a fault that lasts), see ParticleFilter::adaptFaultFraction.
  // Equal to fault_fraction: a fixed share. [fault_fraction, 1)
  double fault_fraction_max = 0.5;
  // While the filter's share is at or above this, it updates on every scan
  // (update_min_d and update_min_a wait for odometry that is wrong). > 0;
  // above fault_fraction_max: never.
  double fault_suspect_fraction = 0.1;
  // How far a robot whose odometry stalled may still have moved (m). >= 0
  double fault_margin = 0.1;
};

/// The longest step one filter update makes (see above): steps up to it have
/// the alphas' noise; longer ones, that of the updates they span. Infinite:
/// every step is one update's (the textbook model).
struct OneUpdateStep {
  double distance = std::numeric_limits<double>::infinity();  // m
  double angle = std::numeric_limits<double>::infinity();     // rad
};

/// The parameters of OdometryMotionParams (parameter_table.h).
const ParameterTable<OdometryMotionParams>& odometryMotionParameters();

/// Throws std::invalid_argument naming the first value out of range.
void validate(const OdometryMotionParams& params);

/// The odometry step split into rotation, translation, rotation.
struct OdometryStep {
  double rot1;
  double trans;
  double rot2;
};

class OdometryMotionModel {
 public:
  /// Throws std::invalid_argument (see validate(), and a non-positive step).
  explicit OdometryMotionModel(const OdometryMotionParams& params,
                               const OneUpdateStep& update_step = {});

  const OdometryMotionParams& params() const { return params_; }

  /// Decomposes the odometry motion from `from` to `to` (both in the odom frame).
  static OdometryStep decompose(const Pose2& from, const Pose2& to);

  /// Moves every particle by the noisy odometry motion from `from` to `to`.
  void apply(const Pose2& from, const Pose2& to, ParticleSet* particles, Random* random) const;
  /// The same with `fault_fraction` in place of the parameter's (the filter
  /// adapts it), writing into `faulty` (when not null) which particles took
  /// a fault (1) and which the odometry's step (0), on up to `threads`
  /// threads: each block of particles draws from its own stream
  /// (particle_blocks.h), so the result is the same for any thread count.
  /// In an update that brings a share `view_share` < 1 of a new view
  /// (view_share.h), each component's variance below a view's size is linear
  /// in it, and the stalled particles' spread is fault_margin times the share.
  void apply(const Pose2& from, const Pose2& to, double fault_fraction, ParticleSet* particles,
             Random* random, std::vector<uint8_t>* faulty, int threads = 1,
             double view_share = 1.0) const;

 private:
  void applyDifferential(const Pose2& from, const Pose2& to, double fault_fraction,
                         double view_share, ParticleSet* particles, BlockStreams* random,
                         uint8_t* faulty, int threads) const;
  void applyOmni(const Pose2& from, const Pose2& to, double fault_fraction, double view_share,
                 ParticleSet* particles, BlockStreams* random, uint8_t* faulty, int threads) const;

  OdometryMotionParams params_;
  OneUpdateStep update_step_;
};

}  // namespace pf

// Odometry motion model: moves every particle by the motion the wheel odometry
// reports, with noise that grows with the motion.
//
// Differential drive: "sample_motion_model_odometry" of Thrun, Burgard & Fox,
// "Probabilistic Robotics" (2005), table 5.6. The odometry step is split into
// a rotation rot1 towards the direction of travel, a translation trans and a
// final rotation rot2; each is perturbed with a standard deviation of
//   rot:   sqrt(alpha1 * rot^2 + alpha2 * trans^2)
//   trans: sqrt(alpha3 * trans^2 + alpha4 * (rot1^2 + rot2^2))
// Two refinements over the textbook: a robot that drives backwards has
// rot1 close to pi, which must not be mistaken for a large rotation, so the
// rotation noise uses the smaller of |rot1| and |pi - rot1|; and for tiny
// translations the direction of travel is meaningless, so rot1 is taken as 0.
//
// One filter update's step: the alphas describe the noise of the step one
// update makes, as in amcl, whose updates come every update_min_d of travel.
// A longer step (scans far apart) stands for several updates, and its
// variance adds up as theirs would, linearly in its length, instead of with
// its square: each v^2 above becomes v * min(v, one update's v). Left
// quadratic, a long step's direction of travel is so noisy that the
// particles fall short of the odometry on average, and along a corridor the
// cloud falls behind the robot (docs/design.md, "A long step's noise").
//
// Omnidirectional: the step is a translation in the robot frame (forward and
// strafe) plus a rotation, with amcl's omni convention for the alphas:
//   trans:  sqrt(alpha3 * trans^2 + alpha1 * rot^2)
//   rot:    sqrt(alpha4 * rot^2 + alpha2 * trans^2)
//   strafe: sqrt(alpha1 * rot^2 + alpha5 * trans^2)
//
// Odometry faults: the Gaussian above assumes that the wheels report the
// motion up to a few per cent. Real odometry sometimes does not, in two ways
// that a Gaussian cannot cover: it reports motion the robot did not make
// (wheels spinning on a threshold, a stalled or held robot), and it reports
// the wrong direction (encoders that count ticks without their sign, so a
// reversing robot is logged as driving forwards: the CARMEN logs do this in
// 5 % of their steps on fr079). A Gaussian then puts no particle where the
// robot is, and the filter drifts away while every scan still fits roughly.
// So the model is a mixture (Thrun, Burgard & Fox, section 6.3.1, applied to
// motion: a reliable and an unreliable component): a share fault_fraction of
// the particles take, half of them, the reversed translation (with the same
// noise) and the other half no translation (uniform within +-fault_margin).
// The scans decide which particles were right; when the odometry was, the
// faulty ones die at the next resampling. Faults come in runs (a robot
// reverses for a while), so the filter sets the next step's share from this
// scan's evidence for a fault, between fault_fraction and fault_fraction_max
// (OdometryFaultTracker): a small share while the odometry is right, many
// particles in the fault while it lasts, and none while the scan cannot pin
// the position along the direction of travel. A uniform spread
// over every translation in between was tried: in long corridors, where the scans say little about
// the position along them, it smeared the estimate along the corridor (Intel lab) more than the two
// discrete faults do.
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
  /// (new_view.h), each component's variance below a view's size is linear
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

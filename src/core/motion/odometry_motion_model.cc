#include "pf_localization/core/motion/odometry_motion_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pf_localization/core/filter/view_share.h"
#include "pf_localization/core/util/fast_math.h"
#include "pf_localization/core/util/parameter_table.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {
namespace {

// Below this translation (m) the direction of travel is noise, not motion.
constexpr double kMinTranslationForHeading = 0.01;

// Particles moved per pass of applyDifferential: its four intermediate
// arrays (32 KiB) stay within a core's L1/L2 cache.
constexpr std::size_t kMotionChunk = 1024;

// v^2 for a step of v up to one update's `one`; beyond it, the sum of the
// squares of the v / one updates of length `one` the step stands for. In an
// update that brings part of a view (`view`: the view's size, 0 for a whole
// view), a component shorter than the view has v * view, its share of one
// view's variance, so that the partial updates of a view add up to at least
// the noise of the one update they replace.
double spanSquare(double v, double one, double view) {
  return v * std::min(std::max(v, view), std::max(one, view));
}

// A rotation of nearly pi before a straight move is a robot reversing, not
// turning around: its noise must be that of the small angle it really turned.
double rotationMagnitude(double rot) {
  return std::min(std::fabs(rot), std::fabs(angleDiff(rot, M_PI)));
}

// The translation one particle takes: the odometry's with Gaussian noise,
// or, for the share fault_fraction of the particles, half the time the
// reversed one (with the same noise) and half the time none (uniform within
// +-margin). *fault says which. See the header.
// (Always inlined: the loops below draw from a local copy of their stream,
// which must not have its address escape into a call; see random.h.)
__attribute__((always_inline)) inline double sampleTranslation(double trans, double sigma,
                                                               double fault_fraction, double margin,
                                                               Random* random, uint8_t* fault) {
  if (fault_fraction > 0.0) {
    const double u = random->uniform();
    *fault = u < fault_fraction ? 1 : 0;
    if (u < 0.5 * fault_fraction) return -trans + random->gaussian(sigma);
    if (u < fault_fraction) return random->uniform(-margin, margin);
  } else {
    *fault = 0;
  }
  return trans - random->gaussian(sigma);
}

// What a differential step draws from (see applyDifferential): the
// odometry's rotations and translation, their noise, and the fault share.
struct DifferentialDraws {
  OdometryStep step;
  double sigma_rot1, sigma_trans, sigma_rot2;
  double fault_fraction, fault_margin;
};

// The random part of a differential step for `count` particles, one
// particle after the other from `stream`: each heading turned by its first
// rotation (the heading of travel), its translation, its second rotation,
// and whether it took a fault. Everything the loop reads is a local or a
// value here, the stream too (copied in and back): a store through the
// char pointer `faulty` might otherwise change it, and the stream's state
// and every other operand were reloaded for each particle.
void drawDifferential(const DifferentialDraws d, Random* stream, std::size_t count, double* yaw,
                      double* trans, double* turn2, uint8_t* faulty) {
  Random random = *stream;
  for (std::size_t i = 0; i < count; ++i) {
    const double r1 = d.step.rot1 - random.gaussian(d.sigma_rot1);
    trans[i] = sampleTranslation(d.step.trans, d.sigma_trans, d.fault_fraction, d.fault_margin,
                                 &random, &faulty[i]);
    turn2[i] = d.step.rot2 - random.gaussian(d.sigma_rot2);
    yaw[i] += r1;
  }
  *stream = random;
}

std::string kindName(OdometryMotionParams::Kind kind) {
  return kind == OdometryMotionParams::Kind::kOmni ? "omni" : "diff";
}

void setKind(OdometryMotionParams& p, const std::string& word, const ParamInfo& info) {
  checkValue(info, word);
  // amcl's "-corrected" variants fixed bugs of its own; the models here are the corrected ones.
  p.kind = word.rfind("omni", 0) == 0 ? OdometryMotionParams::Kind::kOmni
                                      : OdometryMotionParams::Kind::kDifferential;
}

}  // namespace

const ParameterTable<OdometryMotionParams>& odometryMotionParameters() {
  using P = OdometryMotionParams;
  using I = ParamInfo;
  static const I kind = I("odom_model_type", "", "diff (differential drive) or omni (holonomic)")
                            .oneOf({"diff", "diff-corrected", "omni", "omni-corrected"})
                            .amcl();
  const auto alpha = [](const char* name, const char* unit, const char* what) {
    return I(name, unit, what).in(Range::atLeast(0)).amcl().live(0, 10);
  };
  static const ParameterTable<P> table = {
      computed<P, std::string>([](const P& p) { return kindName(p.kind); },
                               [](P& p, const std::string& w) { setKind(p, w, kind); }, kind),
      member(&P::alpha1, alpha("odom_alpha1", "rad^2/rad^2", "rotation noise from rotation")),
      member(&P::alpha2, alpha("odom_alpha2", "rad^2/m^2", "rotation noise from translation")),
      member(&P::alpha3, alpha("odom_alpha3", "m^2/m^2", "translation noise from translation")),
      member(&P::alpha4, alpha("odom_alpha4", "m^2/rad^2", "translation noise from rotation")),
      member(&P::alpha5, alpha("odom_alpha5", "m^2/m^2", "strafe noise from translation (omni)")),
  };
  return table;
}

void validate(const OdometryMotionParams& p) {
  checkRanges(odometryMotionParameters(), p);
  requireParameter(p.fault_fraction >= 0.0 && p.fault_fraction < 1.0,
                   "OdometryMotionParams::fault_fraction", "in [0, 1)", p.fault_fraction);
  requireParameter(p.fault_fraction_max >= p.fault_fraction && p.fault_fraction_max < 1.0,
                   "OdometryMotionParams::fault_fraction_max", "in [fault_fraction, 1)",
                   p.fault_fraction_max);
  requireParameter(p.fault_suspect_fraction > 0.0, "OdometryMotionParams::fault_suspect_fraction",
                   "> 0", p.fault_suspect_fraction);
  requireParameter(p.fault_margin >= 0.0 && std::isfinite(p.fault_margin),
                   "OdometryMotionParams::fault_margin", ">= 0", p.fault_margin);
}

OdometryMotionModel::OdometryMotionModel(const OdometryMotionParams& params,
                                         const OneUpdateStep& update_step)
    : params_((validate(params), params)), update_step_(update_step) {
  requireParameter(update_step.distance > 0.0, "OneUpdateStep::distance", "> 0",
                   update_step.distance);
  requireParameter(update_step.angle > 0.0, "OneUpdateStep::angle", "> 0", update_step.angle);
}

OdometryStep OdometryMotionModel::decompose(const Pose2& from, const Pose2& to) {
  const double dx = to.x - from.x;
  const double dy = to.y - from.y;
  const double trans = std::hypot(dx, dy);
  const double rot1 =
      trans < kMinTranslationForHeading ? 0.0 : angleDiff(std::atan2(dy, dx), from.yaw);
  const double rot2 = angleDiff(angleDiff(to.yaw, from.yaw), rot1);
  return {rot1, trans, rot2};
}

void OdometryMotionModel::apply(const Pose2& from, const Pose2& to, ParticleSet* particles,
                                Random* random) const {
  apply(from, to, params_.fault_fraction, particles, random, nullptr);
}

void OdometryMotionModel::apply(const Pose2& from, const Pose2& to, double fault_fraction,
                                ParticleSet* particles, Random* random,
                                std::vector<uint8_t>* faulty, int threads,
                                double view_share) const {
  thread_local std::vector<uint8_t> unused;
  std::vector<uint8_t>* flags = faulty != nullptr ? faulty : &unused;
  flags->resize(particles->size());
  BlockStreams& streams = threadScratch<BlockStreams>();
  streams.reset(particles->size(), random);
  if (params_.kind == OdometryMotionParams::Kind::kOmni) {
    applyOmni(from, to, fault_fraction, view_share, particles, &streams, flags->data(), threads);
  } else {
    applyDifferential(from, to, fault_fraction, view_share, particles, &streams, flags->data(),
                      threads);
  }
}

void OdometryMotionModel::applyDifferential(const Pose2& from, const Pose2& to,
                                            double fault_fraction, double view_share,
                                            ParticleSet* particles, BlockStreams* streams,
                                            uint8_t* faulty, int threads) const {
  const OdometryStep step = decompose(from, to);
  const bool partial = view_share < 1.0;
  const double view_angle = partial ? kViewAngle : 0.0;
  const double view_distance = partial ? kViewDistance : 0.0;
  const double rot1_2 = spanSquare(rotationMagnitude(step.rot1), update_step_.angle, view_angle);
  const double rot2_2 = spanSquare(rotationMagnitude(step.rot2), update_step_.angle, view_angle);
  const double trans2 = spanSquare(step.trans, update_step_.distance, view_distance);
  const DifferentialDraws draws{
      step, std::sqrt(params_.alpha1 * rot1_2 + params_.alpha2 * trans2),
      std::sqrt(params_.alpha3 * trans2 + params_.alpha4 * (rot1_2 + rot2_2)),
      std::sqrt(params_.alpha1 * rot2_2 + params_.alpha2 * trans2), fault_fraction,
      // A stalled robot's spread, per view: a share of one covers that share.
      params_.fault_margin * view_share};

  // Two passes per chunk of a block: the random draws, one particle after
  // the other (the random stream is the same as drawing and moving each
  // particle in turn), then the headings' sines and cosines for the chunk at
  // once (sinCos vectorises; one C library call per particle was most of this
  // step). A chunk's intermediate values stay in the core's cache: at a
  // million particles, whole-block arrays made two threads wait on memory.
  ParticleSet& p = *particles;
  forEachBlock(p.size(), threads, [&](std::size_t b, std::size_t begin, std::size_t end) {
    Random* stream = streams->stream(b);
    for (std::size_t from = begin; from < end; from += kMotionChunk) {
      const std::size_t to = std::min(end, from + kMotionChunk);
      alignas(64) double trans[kMotionChunk], turn2[kMotionChunk], s[kMotionChunk], c[kMotionChunk];
      // p.yaw becomes the heading of travel until the last pass.
      drawDifferential(draws, stream, to - from, p.yaw.data() + from, trans, turn2, faulty + from);
      sinCos(p.yaw.data() + from, to - from, s, c);
      for (std::size_t i = from; i < to; ++i) {
        p.x[i] += trans[i - from] * c[i - from];
        p.y[i] += trans[i - from] * s[i - from];
        p.yaw[i] = normalizeAngle(p.yaw[i] + turn2[i - from]);
      }
    }
  });
}

void OdometryMotionModel::applyOmni(const Pose2& from, const Pose2& to, double fault_fraction,
                                    double view_share, ParticleSet* particles,
                                    BlockStreams* streams, uint8_t* faulty, int threads) const {
  const double dx = to.x - from.x;
  const double dy = to.y - from.y;
  const double trans = std::hypot(dx, dy);
  const double rot = angleDiff(to.yaw, from.yaw);
  // Direction of travel relative to the heading: omni robots may move sideways.
  const double bearing =
      trans < kMinTranslationForHeading ? 0.0 : angleDiff(std::atan2(dy, dx), from.yaw);
  const bool partial = view_share < 1.0;
  const double trans2 = spanSquare(trans, update_step_.distance, partial ? kViewDistance : 0.0);
  const double rot2 = spanSquare(std::fabs(rot), update_step_.angle, partial ? kViewAngle : 0.0);
  const double fault_margin = params_.fault_margin * view_share;
  const double sigma_trans = std::sqrt(params_.alpha3 * trans2 + params_.alpha1 * rot2);
  const double sigma_rot = std::sqrt(params_.alpha4 * rot2 + params_.alpha2 * trans2);
  const double sigma_strafe = std::sqrt(params_.alpha1 * rot2 + params_.alpha5 * trans2);

  ParticleSet& p = *particles;
  forEachBlock(p.size(), threads, [&](std::size_t b, std::size_t begin, std::size_t end) {
    Random random = *streams->stream(b);  // in registers, as in applyDifferential
    for (std::size_t i = begin; i < end; ++i) {
      const double t =
          sampleTranslation(trans, sigma_trans, fault_fraction, fault_margin, &random, &faulty[i]);
      const double s = random.gaussian(sigma_strafe);
      const double heading = p.yaw[i] + bearing;
      p.x[i] += t * std::cos(heading) - s * std::sin(heading);
      p.y[i] += t * std::sin(heading) + s * std::cos(heading);
      p.yaw[i] = normalizeAngle(p.yaw[i] + rot + random.gaussian(sigma_rot));
    }
    *streams->stream(b) = random;
  });
}

}  // namespace pf

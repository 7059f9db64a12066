// Scan-to-map refinement: the pose at which the scan's end points lie best
// on the map's obstacles, found by Gauss-Newton from the filter's estimate.
//
// The particle filter's estimate is the weighted mean of a cloud whose
// particles are spread by the motion noise, so it wobbles by centimetres from
// update to update. A scan of a few dozen beams pins the pose down far more
// tightly than that, once the pose is known well enough to match it: this is
// the Ceres scan matcher of Cartographer (Hess et al., "Real-Time Loop Closure
// in 2D LIDAR SLAM", ICRA 2016), here on the distance field instead of a
// probability grid. For end points p_i (robot frame) and the pose T, it
// minimises
//   sum_i rho(D(T p_i) - wall_offset) / beam_std^2 + prior(T)
// where D is the bicubic interpolation of the distance to the nearest
// obstacle (bicubic_distance_field.h) and rho the Cauchy loss with scale
// cauchy_scale, solved by iteratively reweighted Gauss-Newton with a
// backtracking line search. Beams whose end point lies outlier_distance or
// further from any obstacle (a person, a door opened since the map was made,
// nothing mapped) are truncated: they cost a constant and do not pull.
//
// prior(T) is optional: 1/2 (T - start)^T C^-1 (T - start) for the filter's
// cloud covariance C (the maximum a posteriori pose is found then): what the
// scan barely constrains,
// such as the position along a corridor with a door frame or two, then stays
// near the filter's estimate instead of following the scan's noise.
// Directions that nothing constrains are left alone: the step is solved with
// the pseudo-inverse of the Gauss-Newton Hessian. The fit's covariance says
// nothing about the directions the scan does not constrain.
//
// The result is rejected, and the filter's estimate kept, when too few beams
// match, when the fit constrains nothing, or when it moves further than
// max_translation / max_rotation: a jump that large means the scan fits
// another place better, and choosing between hypotheses is the filter's job.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <optional>
#include <string>

#include "pf_localization/core/map/bicubic_distance_field.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

struct ScanRefinerParams {
  // Beams fitted per scan at a filter update, evenly spaced over the valid
  // ones (<= 0: all). More than the particles are weighed with: the fit runs
  // once per scan, not once per particle, and which few beams a dropout
  // leaves would otherwise shift the fit from scan to scan. 180 is half a
  // 0.5-degree scan: on every bag with a reference, fitting all beams is no
  // more precise (docs/design.md, "What refinement costs").
  int max_beams = 180;
  // Beams fitted on a scan between updates. That fit only has to carry the
  // last update's pose over the odometry's drift of a fraction of a second,
  // from a start within millimetres of it.
  int max_beams_between_updates = 90;
  int max_iterations = 20;        // Gauss-Newton iterations at most
  double outlier_distance = 0.3;  // m: end points this far from any obstacle do not pull
  double cauchy_scale = 0.05;     // m: residuals well beyond this are down-weighted (Cauchy)
  // m: the distance from an occupied cell's centre at which a beam ends on
  // the wall. The field measures distances to cell centres; a laser stops at
  // the face of the first occupied cell, which a ray-cast simulation puts
  // half a cell from its centre, and a mapped wall somewhere inside its cells.
  double wall_offset = 0.0;
  double min_matched_fraction = 0.3;  // of the beams, ending within outlier_distance: fewer rejects
  int min_matched_beams = 8;          // and at least this many
  double max_translation = 0.5;       // m: a longer move is rejected
  double max_rotation = 0.3;          // rad: a larger turn is rejected
  // m: floor of the per-beam residual std dev in the covariance. The map's
  // cells quantise the walls (0.05 m cells: 0.014 m std), so no fit is
  // better than that however small its residuals.
  double min_beam_std = 0.015;
  // m: the std dev of a beam's distance to the wall, which weighs the scan
  // against the prior (the cloud's covariance) in the fit.
  double beam_std = 0.03;
  // A direction whose Hessian eigenvalue is below this fraction of the
  // largest one (yaw scaled by 1 m) is unconstrained.
  double degeneracy_ratio = 1e-3;
  // m (and rad times 1 m): a smaller Gauss-Newton step ends the iterations.
  // The Cauchy-reweighted iterations converge linearly, so a tighter bound
  // buys tenths of a millimetre for twice the iterations.
  double convergence = 1e-3;
};

/// Throws std::invalid_argument naming the first parameter out of range (with
/// its refine_ parameter name) and its valid range.
void validate(const ScanRefinerParams& params);

/// Why a scan fit was not used (the estimate of the cloud stands).
enum class ScanRejection {
  kNone,                // accepted, or no fit was tried
  kRefinementOff,       // refine_estimate is off
  kFilterLost,          // the filter is lost: its estimate is no start for a fit
  kNotMovedSinceFit,    // standing still since the last accepted fit, which stands
  kTooFewMatchedBeams,  // too few beams end near a mapped obstacle
  kDegenerate,          // the scan constrains no direction of the pose
  kMovedTooFar,         // beyond max_translation / max_rotation: another place fits better
};

/// A few words for `rejection`, e.g. "too few matched beams".
const char* toString(ScanRejection rejection);

struct ScanRefinement {
  bool accepted = false;
  ScanRejection rejection = ScanRejection::kNone;  // why not, when !accepted
  std::string rejection_detail;                    // the figures behind it, for the log
  Pose2 pose;                                      // the refined pose when accepted, else the start
  // The fit's covariance (x, y, yaw): the residual variance times the
  // inverse Hessian, widened for the beams' correlation, plus the error of
  // the map's walls, one offset per wall (scan_refiner.cc, kIndependentBeams,
  // mapErrorCovariance); zero in the directions the scan does not constrain.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int iterations = 0;
  int matched_beams = 0;      // ending within outlier_distance, at the final pose
  double rms_distance = 0.0;  // m, of the matched beams, at the final pose
  // m^2: the scan's robust cost at the final pose (the sum of rho over the
  // beams, truncated ones included), without the prior. Two fits of the same
  // prepared scan compare by it: the lower lies better on the map.
  double scan_cost = 0.0;
  double translation = 0.0;  // m moved from the start
  double rotation = 0.0;     // rad turned from the start
};

class ScanRefiner {
 public:
  /// Keeps a reference to `field`, which must outlive the refiner.
  /// Throws std::invalid_argument (see validate()).
  ScanRefiner(const DistanceField& field, const ScanRefinerParams& params);

  const ScanRefinerParams& params() const { return params_; }

  /// The pose near `start` that best fits `scan` to the map, or `start`
  /// with the reason the fit was rejected.
  ScanRefinement refine(const PreparedScan& scan, const Pose2& start) const;
  /// The same with a Gaussian prior at `start` (x, y, yaw covariance; empty:
  /// none): the maximum a posteriori pose, so that what the scan barely
  /// constrains stays near the start instead of following the noise.
  ScanRefinement refine(const PreparedScan& scan, const Pose2& start,
                        const std::optional<Eigen::Matrix3d>& prior_covariance) const;

 private:
  struct Evaluation;
  struct MatchedBeam;
  struct BeamSamples;
  /// The field at the end point of each beam of `scan` placed at `pose`,
  /// and each matched beam's Cauchy weight and robust cost.
  void sampleBeams(const PreparedScan& scan, const Pose2& pose, BeamSamples* out) const;
  /// Visits the beams of `scan`, sampled in `at`, in scan order:
  /// matched(beam) for each that ends within outlier_distance of a mapped
  /// obstacle, with its residual and Cauchy weight; outlier() for each other
  /// one.
  template <typename Matched, typename Outlier>
  void forEachBeam(const PreparedScan& scan, const BeamSamples& at, Matched&& matched,
                   Outlier&& outlier) const;
  /// The scan's cost and Gauss-Newton system at `pose`; `*samples` becomes
  /// the beams sampled there.
  Evaluation evaluate(const PreparedScan& scan, const Pose2& pose, BeamSamples* samples) const;
  /// The scan's cost over beam_std^2 plus the prior's, at `at`.
  double totalCost(const Evaluation& e, const Pose2& at, const Pose2& start,
                   const Eigen::Matrix3d& prior_information) const;
  /// Gauss-Newton with a backtracking line search from *fitted (evaluated in
  /// *fitted_evaluation, with its beams sampled in *fitted_samples), all
  /// three updated to the fit. Returns the iterations taken.
  int minimise(const PreparedScan& scan, const Pose2& start,
               const Eigen::Matrix3d& prior_information, Pose2* fitted,
               Evaluation* fitted_evaluation, BeamSamples* fitted_samples) const;

  // The pose's covariance from the map's error: every wall the beams end on
  // (a run of beams along one line of the map) is drawn with an offset of
  // its own, uniform over a cell, shared by all its beams. `fitted`: the
  // beams sampled at the fitted pose; `eig`: the scan's Hessian there.
  Eigen::Matrix3d mapErrorCovariance(
      const PreparedScan& scan, const BeamSamples& fitted,
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eig) const;
  BicubicDistanceField field_;
  ScanRefinerParams params_;
  // m^2: the robust cost of a beam beyond outlier_distance, the same for all.
  double outlier_cost_;
};

/// What a scan fit's covariance (ScanRefinement::covariance: zero in the
/// directions the scan does not constrain) says: its information, the
/// pseudo-inverse, in which those directions carry none, and the projector
/// onto them (zero when the scan pinned all three).
struct FitInformation {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d open = Eigen::Matrix3d::Zero();
};
FitInformation fitInformation(const Eigen::Matrix3d& fit);

/// The covariance of the pose that `fit` (a scan fit's: zero in the
/// directions the scan does not constrain, which carry no information) and
/// `prior` (the cloud's) give together: their informations added, the
/// fit's through its pseudo-inverse. Along a corridor's length, where the fit
/// says nothing, it is the prior's; across, the sharper of the two and
/// sharper still. For publishing a refined pose with what is known of it.
Eigen::Matrix3d fusedCovariance(const Eigen::Matrix3d& fit, const Eigen::Matrix3d& prior);

/// A covariance at least as wide as both `a` and `b` in every direction (C -
/// a and C - b positive semi-definite), and no wider than needed along their
/// common principal axes: both are whitened by a + b, in which they share
/// eigenvectors, and the larger variance is taken along each. For publishing
/// a refined pose without claiming more certainty than the cloud has.
Eigen::Matrix3d coveringCovariance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

/// `to` - `from` as (x, y, yaw), the yaw difference wrapped.
Eigen::Vector3d poseDifference(const Pose2& to, const Pose2& from);

/// The squared Mahalanobis length of `d` in a spread of `covariance`; +inf
/// when the covariance (with a 1e-9 ridge) cannot be inverted.
double squaredMahalanobis(const Eigen::Vector3d& d, const Eigen::Matrix3d& covariance);

}  // namespace pf

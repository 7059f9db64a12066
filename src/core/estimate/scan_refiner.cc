#include "pf_localization/core/estimate/scan_refiner.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pf_localization/core/util/parameter_table.h"

namespace pf {
namespace {

bool finite(double v) { return std::isfinite(v); }

// Yaw enters the eigen-analysis scaled by this length, so that a radian
// weighs as much as the metre a beam's end point moves at 1 m range.
constexpr double kYawScale = 1.0;  // m

// A map draws each straight wall once, somewhere inside the cells along it:
// its error is one offset for the whole wall, uniform over a cell (variance
// resolution^2 / 12), which no number of beams on that wall averages away.
// The fit's covariance therefore carries that error explicitly
// (ScanRefiner::mapErrorCovariance): the beams are grouped into walls, and
// each wall's offset moves the fitted pose by the sum of its beams' shares.
// A beam starts a new wall where the map's normal turns by more than
// kWallTurn (a corner: building walls meet at right angles, while along a
// straight wall the bicubic field's normal wavers by a few degrees) or where
// its end point leaves the line of the previous one by more than a cell (a
// parallel wall farther off, or an object in front of the wall).
constexpr double kWallTurn = 0.5;  // rad

// What is left of the beams' correlation, beyond the walls' offsets (the
// wall's texture within its cells, the scan's own error along a wall, the
// field's interpolation): the residuals of N beams carry the information of
// kIndependentBeams, and the fit's residual covariance is widened by
// N / kIndependentBeams. With the walls' offsets above, the value puts
// 85-99 % of the true poses of every simulated bag (exact truth) inside the
// published 95 % ellipse; docs/design.md, "An honest covariance", has the
// figures for each value tried and the real recordings' it was checked on.
constexpr double kIndependentBeams = 60.0;

// d(distance at the end point)/d(x, y, kYawScale yaw) of the beam ending at
// (px, py) in the robot frame, for a robot turned by (cos, sin) = (c, s).
// d(end point)/d(yaw) = (-s px - c py, c px - s py).
Eigen::Vector3d beamJacobian(const FieldSample& f, double px, double py, double c, double s) {
  return {f.dx, f.dy, (f.dx * (-s * px - c * py) + f.dy * (c * px - s * py)) / kYawScale};
}

std::string text(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

}  // namespace

const char* toString(ScanRejection rejection) {
  switch (rejection) {
    case ScanRejection::kNone:
      return "none";
    case ScanRejection::kRefinementOff:
      return "refine_estimate is off";
    case ScanRejection::kFilterLost:
      return "the filter is lost";
    case ScanRejection::kNotMovedSinceFit:
      return "not moved since the last fit, which stands";
    case ScanRejection::kTooFewMatchedBeams:
      return "too few matched beams";
    case ScanRejection::kDegenerate:
      return "the scan constrains no direction of the pose";
    case ScanRejection::kMovedTooFar:
      return "the fit moved too far";
  }
  return "unknown rejection";
}

void validate(const ScanRefinerParams& p) {
  requireParameter(p.max_iterations >= 1, "refine_max_iterations", ">= 1", p.max_iterations);
  requireParameter(p.outlier_distance > 0.0 && finite(p.outlier_distance),
                   "refine_outlier_distance", "> 0", p.outlier_distance);
  requireParameter(p.cauchy_scale > 0.0 && finite(p.cauchy_scale), "refine_cauchy_scale", "> 0",
                   p.cauchy_scale);
  requireParameter(p.wall_offset >= 0.0 && p.wall_offset < p.outlier_distance, "refine_wall_offset",
                   "in [0, refine_outlier_distance)", p.wall_offset);
  requireParameter(p.min_matched_fraction >= 0.0 && p.min_matched_fraction <= 1.0,
                   "refine_min_matched_fraction", "in [0, 1]", p.min_matched_fraction);
  requireParameter(p.min_matched_beams >= 3, "refine_min_matched_beams", ">= 3",
                   p.min_matched_beams);
  requireParameter(p.max_translation >= 0.0 && finite(p.max_translation), "refine_max_translation",
                   ">= 0", p.max_translation);
  requireParameter(p.max_rotation >= 0.0 && p.max_rotation <= M_PI, "refine_max_rotation",
                   "in [0, pi]", p.max_rotation);
  requireParameter(p.min_beam_std > 0.0 && finite(p.min_beam_std), "refine_min_beam_std", "> 0",
                   p.min_beam_std);
  requireParameter(p.degeneracy_ratio > 0.0 && p.degeneracy_ratio < 1.0, "refine_degeneracy_ratio",
                   "in (0, 1)", p.degeneracy_ratio);
  requireParameter(p.beam_std > 0.0 && finite(p.beam_std), "refine_beam_std", "> 0", p.beam_std);
  requireParameter(p.convergence > 0.0 && finite(p.convergence), "refine_convergence", "> 0",
                   p.convergence);
}

// The robust cost at one pose, and optionally the Gauss-Newton system.
struct ScanRefiner::Evaluation {
  double cost = 0.0;
  int matched = 0;
  double sum_weight = 0.0;
  double sum_weighted_sq = 0.0;                        // sum of w r^2 over matched beams
  double sum_sq = 0.0;                                 // sum of r^2 over matched beams
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();   // J^T W J, yaw scaled by kYawScale
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // J^T W r
};

ScanRefiner::ScanRefiner(const DistanceField& field, const ScanRefinerParams& params)
    : field_(field), params_((validate(params), params)) {
  const double k2 = params_.cauchy_scale * params_.cauchy_scale;
  const double truncated = params_.outlier_distance - params_.wall_offset;
  outlier_cost_ = 0.5 * k2 * std::log1p(truncated * truncated / k2);
}

// One matched beam, as ScanRefiner::forEachBeam gives it.
struct ScanRefiner::MatchedBeam {
  FieldSample f;  // the field at the end point
  double px, py;  // the end point in the robot frame
  double mx, my;  // the end point on the map
  double c, s;    // the pose's cos and sin of yaw
  double r;       // residual: distance to the wall's line (wall_offset off)
  double w;       // the Cauchy weight, rho'(r^2 / 2) = 1 / (1 + r^2 / cauchy_scale^2)
  double rho;     // m^2: the robust cost, rho(r^2 / 2)
};

// The field at every beam's end point, the scan placed at one pose.
struct ScanRefiner::BeamSamples {
  double c = 1.0, s = 0.0;     // the pose's cos and sin of yaw
  std::vector<double> mx, my;  // the end points on the map
  std::vector<FieldSample> f;  // the field there
  // Of each beam; w and rho of the matched ones only:
  std::vector<double> q;    // 1 + r^2 / cauchy_scale^2, r the residual
  std::vector<double> w;    // the Cauchy weight, 1 / q
  std::vector<double> rho;  // m^2: the robust cost, cauchy_scale^2 / 2 log q
};

void ScanRefiner::sampleBeams(const PreparedScan& scan, const Pose2& pose, BeamSamples* out) const {
  const std::size_t n = scan.size();
  out->c = std::cos(pose.yaw);
  out->s = std::sin(pose.yaw);
  out->mx.resize(n);
  out->my.resize(n);
  out->f.resize(n);
  const double c = out->c, s = out->s;
  for (std::size_t b = 0; b < n; ++b) {
    const double px = scan.x[b], py = scan.y[b];
    out->mx[b] = pose.x + c * px - s * py;
    out->my[b] = pose.y + s * px + c * py;
  }
  field_.sample(out->mx.data(), out->my.data(), n, out->f.data());
  // Each beam's weight, and the matched beams' costs, in loops of their own:
  // the divisions of all beams then overlap, and the sums of evaluate() stay
  // in registers, which every call to log would spill.
  const double k2 = params_.cauchy_scale * params_.cauchy_scale;
  std::vector<double>&q = out->q, &w = out->w, &rho = out->rho;
  q.resize(n);
  w.resize(n);
  rho.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    const double r = out->f[b].distance - params_.wall_offset;
    q[b] = 1.0 + r * r / k2;
    w[b] = 1.0 / q[b];
  }
  for (std::size_t b = 0; b < n; ++b) {
    if (out->f[b].distance < params_.outlier_distance) rho[b] = 0.5 * k2 * std::log(q[b]);
  }
}

template <typename Matched, typename Outlier>
void ScanRefiner::forEachBeam(const PreparedScan& scan, const BeamSamples& at, Matched&& matched,
                              Outlier&& outlier) const {
  MatchedBeam beam;
  beam.c = at.c;
  beam.s = at.s;
  for (std::size_t b = 0; b < scan.size(); ++b) {
    beam.f = at.f[b];
    if (!(beam.f.distance < params_.outlier_distance)) {
      outlier();
      continue;
    }
    beam.px = scan.x[b];
    beam.py = scan.y[b];
    beam.mx = at.mx[b];
    beam.my = at.my[b];
    beam.r = beam.f.distance - params_.wall_offset;
    beam.w = at.w[b];
    beam.rho = at.rho[b];
    matched(static_cast<const MatchedBeam&>(beam));
  }
}

ScanRefiner::Evaluation ScanRefiner::evaluate(const PreparedScan& scan, const Pose2& pose,
                                              BeamSamples* samples) const {
  sampleBeams(scan, pose, samples);
  double cost = 0.0, sum_weight = 0.0, sum_weighted_sq = 0.0, sum_sq = 0.0;
  int matched = 0;
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  forEachBeam(
      scan, *samples,
      [&](const MatchedBeam& beam) {
        cost += beam.rho;
        ++matched;
        sum_weight += beam.w;
        sum_weighted_sq += beam.w * beam.r * beam.r;
        sum_sq += beam.r * beam.r;
        const Eigen::Vector3d j = beamJacobian(beam.f, beam.px, beam.py, beam.c, beam.s);
        hessian.noalias() += beam.w * j * j.transpose();
        gradient.noalias() += beam.w * beam.r * j;
      },
      // Constant beyond the truncation, so the cost stays continuous as
      // beams come and go.
      [&] { cost += outlier_cost_; });
  Evaluation e;
  e.cost = cost;
  e.matched = matched;
  e.sum_weight = sum_weight;
  e.sum_weighted_sq = sum_weighted_sq;
  e.sum_sq = sum_sq;
  e.hessian = hessian;
  e.gradient = gradient;
  return e;
}

ScanRefinement ScanRefiner::refine(const PreparedScan& scan, const Pose2& start) const {
  return refine(scan, start, std::nullopt);
}

namespace {

std::string tooFewMatchedDetail(int matched, int beams, int needed, double outlier_distance) {
  return "only " + std::to_string(matched) + " of " + std::to_string(beams) + " beams end within " +
         text(outlier_distance) + " m of a mapped obstacle (" + std::to_string(needed) +
         " needed): nothing to match";
}

// The prior in the scaled coordinates (x, y, kYawScale yaw): a tiny floor
// keeps a zero covariance from becoming an infinite information.
Eigen::Matrix3d priorInformation(const std::optional<Eigen::Matrix3d>& prior_covariance) {
  Eigen::Matrix3d prior_information = Eigen::Matrix3d::Zero();
  if (prior_covariance) {
    const Eigen::DiagonalMatrix<double, 3> scale(1.0, 1.0, kYawScale);
    const Eigen::Matrix3d scaled = scale * (*prior_covariance) * scale;
    prior_information = (scaled + 1e-6 * Eigen::Matrix3d::Identity()).inverse();
    if (!prior_information.allFinite()) prior_information.setZero();
  }
  return prior_information;
}

// The inverse of the scan's Hessian (eigen-decomposed in `eig`) on the
// directions it constrains (an eigenvalue at least `degeneracy_ratio` of the
// largest), zero on the others; `rank` (unless null): how many it constrains.
Eigen::Matrix3d constrainedInverse(const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eig,
                                   double degeneracy_ratio, int* rank = nullptr) {
  const Eigen::Vector3d lambda = eig.eigenvalues();
  Eigen::Matrix3d inverse = Eigen::Matrix3d::Zero();
  int constrained = 0;
  for (int i = 0; i < 3; ++i) {
    if (lambda(i) < degeneracy_ratio * lambda(2)) continue;
    const Eigen::Vector3d v = eig.eigenvectors().col(i);
    inverse += v * v.transpose() / lambda(i);
    ++constrained;
  }
  if (rank) *rank = constrained;
  return inverse;
}

// The fit's covariance: the residual variance per unit weight (with the
// fitted degrees of freedom taken off, floored by the map's own precision)
// times the pseudo-inverse of the scan's Hessian (eigen-decomposed in
// `eig`), which says nothing about the directions the scan does not
// constrain.
Eigen::Matrix3d fitCovariance(const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eig,
                              double sum_weight, double sum_weighted_sq,
                              const ScanRefinerParams& params) {
  int rank = 0;
  Eigen::Matrix3d cov = constrainedInverse(eig, params.degeneracy_ratio, &rank);
  const double dof = std::max(1.0, sum_weight - rank);
  const double variance =
      std::max(params.min_beam_std * params.min_beam_std, sum_weighted_sq / dof);
  cov *= variance * std::max(1.0, sum_weight / kIndependentBeams);
  // Back from the scaled yaw.
  cov.row(2) /= kYawScale;
  cov.col(2) /= kYawScale;
  return 0.5 * (cov + cov.transpose());
}

}  // namespace

Eigen::Matrix3d ScanRefiner::mapErrorCovariance(
    const PreparedScan& scan, const BeamSamples& fitted,
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eig) const {
  // The fitted pose moves by H^+ J^T W dr for residual changes dr (the
  // Gauss-Newton step, on the constrained directions only); a wall's offset
  // changes the residuals of all its beams at once.
  const Eigen::Matrix3d h_inverse = constrainedInverse(eig, params_.degeneracy_ratio);
  const double resolution = field_.resolution();
  const double cos_wall_turn = std::cos(kWallTurn);
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  // The pose's move per metre of the current wall's offset.
  Eigen::Vector3d wall = Eigen::Vector3d::Zero();
  bool on_wall = false;
  double normal_x = 0.0, normal_y = 0.0, last_x = 0.0, last_y = 0.0;
  const auto closeWall = [&] {
    sum.noalias() += wall * wall.transpose();
    wall.setZero();
  };
  forEachBeam(
      scan, fitted,
      [&](const MatchedBeam& beam) {
        const double norm = std::hypot(beam.f.dx, beam.f.dy);
        const double nx = norm > 0.0 ? beam.f.dx / norm : 0.0;
        const double ny = norm > 0.0 ? beam.f.dy / norm : 0.0;
        if (on_wall &&
            (nx * normal_x + ny * normal_y < cos_wall_turn ||
             std::fabs(nx * (beam.mx - last_x) + ny * (beam.my - last_y)) > resolution)) {
          closeWall();
        }
        on_wall = true;
        normal_x = nx;
        normal_y = ny;
        last_x = beam.mx;
        last_y = beam.my;
        // Moving the wall by o moves the field with it: the residual changes
        // by o times the field's slope there (below 1 on the wall's line,
        // where the interpolated distance bottoms out).
        wall.noalias() +=
            h_inverse * (beam.w * norm * beamJacobian(beam.f, beam.px, beam.py, beam.c, beam.s));
      },
      [&] {  // no wall: the one before ends
        if (on_wall) closeWall();
        on_wall = false;
      });
  if (on_wall) closeWall();
  Eigen::Matrix3d cov = sum * (resolution * resolution / 12.0);
  // Back from the scaled yaw.
  cov.row(2) /= kYawScale;
  cov.col(2) /= kYawScale;
  return 0.5 * (cov + cov.transpose());
}

double ScanRefiner::totalCost(const Evaluation& e, const Pose2& at, const Pose2& start,
                              const Eigen::Matrix3d& prior_information) const {
  const double inv_beam_variance = 1.0 / (params_.beam_std * params_.beam_std);
  const Eigen::Vector3d d(at.x - start.x, at.y - start.y, kYawScale * angleDiff(at.yaw, start.yaw));
  return e.cost * inv_beam_variance + 0.5 * d.dot(prior_information * d);
}

int ScanRefiner::minimise(const PreparedScan& scan, const Pose2& start,
                          const Eigen::Matrix3d& prior_information, Pose2* fitted,
                          Evaluation* fitted_evaluation, BeamSamples* fitted_samples) const {
  const double inv_beam_variance = 1.0 / (params_.beam_std * params_.beam_std);
  Pose2& pose = *fitted;
  Evaluation& e = *fitted_evaluation;
  double cost = totalCost(e, pose, start, prior_information);
  BeamSamples trial_samples;
  int iterations = 0;
  for (int it = 0; it < params_.max_iterations; ++it) {
    const Eigen::Vector3d d(pose.x - start.x, pose.y - start.y,
                            kYawScale * angleDiff(pose.yaw, start.yaw));
    const Eigen::Matrix3d h = e.hessian * inv_beam_variance + prior_information;
    const Eigen::Vector3d g = e.gradient * inv_beam_variance + prior_information * d;
    // Gauss-Newton with the pseudo-inverse: a direction neither the scan nor
    // the prior constrains (a corridor's length, without a prior) is not
    // moved along, where noise alone would otherwise drag the fit.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(h);
    const Eigen::Vector3d lambda = eig.eigenvalues();  // increasing
    if (!(lambda(2) > 0.0)) break;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (lambda(i) < params_.degeneracy_ratio * lambda(2)) continue;
      const Eigen::Vector3d v = eig.eigenvectors().col(i);
      step -= v * (v.dot(g) / lambda(i));
    }
    if (!step.allFinite()) break;
    iterations = it + 1;
    // Converged: a step this small changes no figure we publish, and the
    // line search below would only spend evaluations failing to improve it.
    if (step.norm() < params_.convergence) break;
    // Backtracking: a full Gauss-Newton step can overshoot where the field
    // bends (corners, the truncation).
    double scale = 1.0;
    bool improved = false;
    for (int k = 0; k < 10; ++k, scale *= 0.5) {
      const Pose2 trial{pose.x + scale * step(0), pose.y + scale * step(1),
                        normalizeAngle(pose.yaw + scale * step(2) / kYawScale)};
      const Evaluation te = evaluate(scan, trial, &trial_samples);
      const double trial_cost = totalCost(te, trial, start, prior_information);
      if (trial_cost < cost) {
        pose = trial;
        e = te;
        std::swap(*fitted_samples, trial_samples);
        cost = trial_cost;
        improved = true;
        break;
      }
    }
    if (!improved || scale * step.norm() < params_.convergence) break;
  }
  return iterations;
}

ScanRefinement ScanRefiner::refine(const PreparedScan& scan, const Pose2& start,
                                   const std::optional<Eigen::Matrix3d>& prior_covariance) const {
  ScanRefinement out;
  out.pose = start;
  const int n = static_cast<int>(scan.size());
  const int needed = std::max(params_.min_matched_beams,
                              static_cast<int>(std::ceil(params_.min_matched_fraction * n)));
  const Eigen::Matrix3d prior_information = priorInformation(prior_covariance);

  Pose2 pose = start;
  BeamSamples samples;
  Evaluation e = evaluate(scan, pose, &samples);
  if (e.matched < needed) {
    out.matched_beams = e.matched;
    out.rejection = ScanRejection::kTooFewMatchedBeams;
    out.rejection_detail = tooFewMatchedDetail(e.matched, n, needed, params_.outlier_distance);
    return out;
  }
  out.iterations = minimise(scan, start, prior_information, &pose, &e, &samples);

  out.matched_beams = e.matched;
  out.translation = std::hypot(pose.x - start.x, pose.y - start.y);
  out.rotation = angleDiff(pose.yaw, start.yaw);
  // The scan's own information, without the prior: what the fit adds.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(e.hessian);
  if (!(eig.eigenvalues()(2) > 0.0)) {
    out.rejection = ScanRejection::kDegenerate;
    out.rejection_detail = "the scan constrains no direction of the pose";
    return out;
  }
  if (e.matched < needed) {
    out.rejection = ScanRejection::kTooFewMatchedBeams;
    out.rejection_detail = tooFewMatchedDetail(e.matched, n, needed, params_.outlier_distance);
    return out;
  }
  if (out.translation > params_.max_translation || std::fabs(out.rotation) > params_.max_rotation) {
    out.rejection = ScanRejection::kMovedTooFar;
    out.rejection_detail =
        "the fit moved " + text(out.translation) + " m and " + text(std::fabs(out.rotation)) +
        " rad (bounds " + text(params_.max_translation) + " m, " + text(params_.max_rotation) +
        " rad): the scan fits another place better, which is for the filter to decide";
    return out;
  }
  out.covariance = fitCovariance(eig, e.sum_weight, e.sum_weighted_sq, params_) +
                   mapErrorCovariance(scan, samples, eig);
  out.rms_distance = std::sqrt(e.sum_sq / e.matched);
  out.scan_cost = e.cost;
  out.pose = pose;
  out.accepted = true;
  return out;
}

FitInformation fitInformation(const Eigen::Matrix3d& fit) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (fit + fit.transpose()));
  const Eigen::Vector3d lambda = eig.eigenvalues();
  FitInformation out;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d v = eig.eigenvectors().col(i);
    // Zero (or rounding-negative) variance: a direction the fit leaves open.
    if (lambda(i) > 1e-12 * std::max(1e-12, lambda(2))) {
      out.information += v * v.transpose() / lambda(i);
    } else {
      out.open += v * v.transpose();
    }
  }
  return out;
}

Eigen::Matrix3d fusedCovariance(const Eigen::Matrix3d& fit, const Eigen::Matrix3d& prior) {
  const Eigen::Matrix3d information = fitInformation(fit).information;
  // The ridge keeps a flat prior (zero variance somewhere) from making the
  // sum singular; it is far below any variance a pose can have.
  const Eigen::Matrix3d prior_information = (prior + 1e-12 * Eigen::Matrix3d::Identity()).inverse();
  if (!prior_information.allFinite()) return prior;
  const Eigen::Matrix3d fused = (information + prior_information).inverse();
  if (!fused.allFinite()) return prior;
  return 0.5 * (fused + fused.transpose());
}

Eigen::Matrix3d coveringCovariance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  // Whitened by M = a + b, a' + b' = I, so a' and b' share eigenvectors and
  // their eigenvalues pair up as (alpha, 1 - alpha). The tiny ridge makes M
  // invertible when both are flat in some direction.
  const Eigen::Matrix3d m = a + b + 1e-12 * Eigen::Matrix3d::Identity();
  const Eigen::LLT<Eigen::Matrix3d> llt(m);
  if (llt.info() != Eigen::Success) return a + b;  // not PSD: the sum covers both anyway
  const Eigen::Matrix3d l = llt.matrixL();
  const Eigen::Matrix3d l_inv = l.inverse();
  const Eigen::Matrix3d aw = l_inv * a * l_inv.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (aw + aw.transpose()));
  const Eigen::Matrix3d& v = eig.eigenvectors();
  const Eigen::Matrix3d bw = l_inv * b * l_inv.transpose();
  Eigen::Vector3d wider;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d vi = v.col(i);
    wider(i) = std::max(vi.dot(aw * vi), vi.dot(bw * vi));
  }
  const Eigen::Matrix3d c = l * v * wider.asDiagonal() * v.transpose() * l.transpose();
  return 0.5 * (c + c.transpose());
}

Eigen::Vector3d poseDifference(const Pose2& to, const Pose2& from) {
  return {to.x - from.x, to.y - from.y, angleDiff(to.yaw, from.yaw)};
}

double squaredMahalanobis(const Eigen::Vector3d& d, const Eigen::Matrix3d& covariance) {
  const Eigen::Matrix3d information = (covariance + 1e-9 * Eigen::Matrix3d::Identity()).inverse();
  return information.allFinite() ? d.dot(information * d) : std::numeric_limits<double>::infinity();
}

}  // namespace pf

#include "pf_localization/core/filter/beam_screen.h"

#include <utility>

namespace pf {
namespace {

// m: a beam ending this close to a mapped obstacle, where the robot is
// believed to be, agrees with the map: it is never taken for something that
// moved in. Two cells of the usual 0.05 m map, about three beam_std.
constexpr double kOnMapDistance = 0.1;

}  // namespace

PreparedBeams::PreparedBeams(const SensorModel& model, const ScreenedScan& scan,
                             std::vector<PreparedScan> steady)
    : steady_(std::move(steady)) {
  if (scan.report.beams_changed > 0) fitting_ = prepareScans(model, scan.fitting);
}

BeamScreen::MapParts BeamScreen::prepare(const DistanceField& field) {
  return {MapEvidence(field), MapChangeLayer(field)};
}

void BeamScreen::setMap(MapParts parts) {
  evidence_.emplace(std::move(parts.evidence));
  layer_.emplace(std::move(parts.layer));
}

BeamScreen::MapParts BeamScreen::releaseMap() {
  MapParts parts{std::move(*evidence_), std::move(*layer_)};
  evidence_.reset();
  layer_.reset();
  changes_.clear();
  return parts;
}

void BeamScreen::setField(const DistanceField& field) {
  evidence_.emplace(field);
  shareMapChanges(true);
}

ScreenedScan BeamScreen::screen(const Pose2& odom, const ScanGroup& measured,
                                const TrackedPose& tracked) {
  const ScanGroup steady = maskTransients(odom, measured, tracked.pose);
  ScreenedScan out{measured, steady, steady, ScreenReport()};
  if (tracked.judges) {
    out.fitting = changes_.mask(*evidence_, steady, *tracked.pose, &fitting_);
  } else {
    changes_.clear();
  }
  out.report.beams_masked = transients_.masked();
  out.report.beams_changed = changes_.masked();
  out.report.map_evidence = changes_.counts();
  out.report.map_agrees = changes_.agrees();
  out.report.map_changed_share = changes_.changedShare();
  return out;
}

ScanGroup BeamScreen::maskTransients(const Pose2& odom, const ScanGroup& measured,
                                     const std::optional<Pose2>& robot) {
  if (!robot) return transients_.mask(odom, measured, {}, &steady_);
  const DistanceField& field = evidence_->field();
  // Two references: std::function holds them without allocating.
  const auto on_map = [&field, &robot](double x, double y) {
    const Pose2 end = compose(*robot, {x, y, 0.0});
    return field.distanceAt(end.x, end.y) < kOnMapDistance;
  };
  return transients_.mask(odom, measured, on_map, &steady_);
}

void BeamScreen::learn(const ScanGroup& measured, const Pose2& estimate, bool lost) {
  if (!layer_ || !changes_.agrees() || lost || !layer_->wants(estimate)) return;
  layer_->add(measured, estimate);
  shareMapChanges(false);
}

std::string BeamScreen::restoreLayer(const std::string& state) {
  if (!layer_) return "no map to restore the map's changes on";
  const std::string error = layer_->decode(state);
  shareMapChanges(false);  // what was cleared, and what was restored
  return error;
}

void BeamScreen::clearLayer() {
  if (!layer_) return;
  layer_->clear();
  shareMapChanges(false);
}

void BeamScreen::shareMapChanges(bool all) {
  if (!layer_ || !evidence_) return;
  if (all) {
    layer_->takeChangedCells();
    const std::size_t cells = static_cast<std::size_t>(layer_->width()) * layer_->height();
    for (std::size_t i = 0; i < cells; ++i) {
      if (layer_->removed(i)) evidence_->setGone(i, true);
      if (layer_->added(i)) evidence_->setAdded(i, true);
    }
    return;
  }
  for (std::size_t i : layer_->takeChangedCells()) {
    evidence_->setGone(i, layer_->removed(i));
    evidence_->setAdded(i, layer_->added(i));
  }
}

}  // namespace pf

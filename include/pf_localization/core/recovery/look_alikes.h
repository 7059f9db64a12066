// Places on the map that look alike, and what each scan says about them.
//
// Rows of identical racks, twin rooms or a symmetric hall give the same scan
// at several poses. A filter that tracked its way into one of them cannot
// tell from the scan that it is not in another, and after a kidnap into a
// twin it stays sure of the wrong one. So, once per map, findMapSymmetries
// finds the rigid motions that carry most of the map's obstacles onto
// obstacles (shifts, and half turns): the peaks of the obstacle grid's
// autocorrelation (shifts) and self-convolution (half turns), computed with
// FFTs on a coarse grid and refined on the map's own cells. Then, per scan,
// LookAlikes::judge places the scan at each motion of the estimate and
// compares fits: a look-alike that fits as well means the scan cannot tell
// the places apart (the published verdict stays "uncertain"); one that fits
// clearly better is where the robot more likely is (recovery moves a share
// of the cloud there). See docs/design.md, "Look-alike places".
#pragma once

#include <cstddef>
#include <vector>

#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/map/map_evidence.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

/// A rigid motion of the map onto itself: a pose p looks like compose(motion, p).
struct MapSymmetry {
  Pose2 motion;
  double overlap = 0.0;  // share of the map's obstacle cells the motion puts on obstacles
};

/// The map's symmetries with an overlap of at least kMinSymmetryOverlap,
/// strongest first, at most kMaxSymmetries.
std::vector<MapSymmetry> findMapSymmetries(const DistanceField& field);

/// A look-alike place and the scans' log-likelihood there.
struct LookAlikePlace {
  Pose2 pose;
  double fit = 0.0;
};

/// What one scan says about the estimate's look-alikes.
struct LookAlikeView {
  double fit = 0.0;                    // the scans' log-likelihood at the estimate
  std::size_t as_good = 0;             // look-alikes fitting within kAsGoodMargin of it, or better
  std::vector<LookAlikePlace> places;  // those look-alikes
  // Motions whose look-alike fits kBetterMargin more than the estimate and
  // within kAsGoodMargin of the best look-alike.
  std::vector<Pose2> better;
  double best_fit = 0.0;  // the best look-alike's log-likelihood (-inf without one)
};

class LookAlikes {
 public:
  /// A half turn or shift must put at least this share of the obstacle cells
  /// on obstacles: twin racks and symmetric halls do, office buildings do
  /// not (design.md, "Look-alike places", gives the figures).
  static constexpr double kMinSymmetryOverlap = 0.4;
  /// Look-alikes closer than this to the estimate are the same place.
  static constexpr double kMinShift = 1.0;  // m
  /// The strongest motions kept per map; each costs a scan placement per update.
  static constexpr std::size_t kMaxSymmetries = 128;
  /// A look-alike whose scan likelihood is at least 1/20 of the estimate's
  /// fits "as well": with an equal prior it would hold 5 % of the weight,
  /// as a hypothesis must (kMinHypothesisShare).
  static constexpr double kAsGoodMargin = 3.0;  // log(20)
  /// ... and one 20 times likelier than the estimate fits "clearly better".
  static constexpr double kBetterMargin = 3.0;
  /// A look-alike counts as better only after fitting clearly better on this
  /// many consecutive updates (about a metre of travel at update_min_d): an
  /// object that is not on the map, seen from one spot, can make a shifted
  /// pose fit better for a scan or three.
  static constexpr int kBetterUpdates = 5;
  /// ... and only where its scan passes the map's obstacles or leaves the
  /// map on at most this share of the beams more than at the estimate
  /// (MapEvidence): a look-alike the changes of a map make fit better sees
  /// through its walls; the place a robot was kidnapped to does not.
  static constexpr double kSeenMargin = 0.2;

  /// Finds the symmetries of `field`'s map (findMapSymmetries).
  void setMap(const DistanceField& field) { setSymmetries(findMapSymmetries(field)); }
  /// A map's symmetries, found beforehand.
  void setSymmetries(std::vector<MapSymmetry> symmetries);
  /// Forgets the streaks of better fits (after an initialisation).
  void restart();
  const std::vector<MapSymmetry>& symmetries() const { return symmetries_; }

  /// Places `scans` at the estimate and at each of its look-alikes (those in
  /// free space) and compares the model's log-likelihoods.
  LookAlikeView judge(const SensorModel& model, const std::vector<PreparedScan>& scans,
                      const Pose2& estimate, const MapEvidence* evidence = nullptr);
  /// The look-alikes (in free space) of each of `held`, the other places a
  /// spread cloud holds, where `scans` fit at least `min_fit`. Such a cloud
  /// may hold no particle near the true place but one a rack bay along it.
  std::vector<LookAlikePlace> placesAround(const SensorModel& model,
                                           const std::vector<PreparedScan>& scans,
                                           const std::vector<Pose2>& held, double min_fit) const;

 private:
  // Appends to `poses` each look-alike of `pose` in free space, and its
  // symmetry's index to `index` when given.
  void lookAlikesOf(const OccupancyGrid& grid, const Pose2& pose, std::vector<Pose2>* poses,
                    std::vector<std::size_t>* index) const;

  std::vector<MapSymmetry> symmetries_;
  std::vector<int> streaks_;  // per symmetry: consecutive updates it fitted clearly better
};

}  // namespace pf

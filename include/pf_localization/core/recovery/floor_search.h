// Which floor of a building the robot is on, when nobody says: global
// localization on every floor at once.
//
// One ParticleFilter per floor, each started globally on that floor's map
// (so each runs GlobalSearch's smoothed likelihood and the confidence
// verdict of estimate.md, as global localization on one map does), all fed
// the same odometry and scans. Each floor's fit is the share of the beams
// that end within `fit_distance` of an obstacle of its map, seen from its
// filter's estimate, averaged over its last `fit_updates` updates: how much
// of the scans the floor's best hypothesis explains. The search names a
// floor only when its fit has exceeded every other floor's by
// `min_fit_margin` for `found_updates` updates in a row and its filter is
// localized. The two confirmations run side by side, not one after the
// other: "localized" already holds a new place for settle_updates updates
// (confidence.h, holdAfterJump), and a run counted only from then on would
// repeat that wait.
// Being localized alone does not tell floors apart: on a floor of the same
// outline laid out otherwise, a filter finds a pose where the beams end
// within confidence.h's hit distance (0.4 m) as well (in the test, both
// floors are localized, hit fraction 1.0, on the scans of one); nor does the
// cloud's mean beam likelihood, which the walls both floors share dominate
// (1.56 against 1.78 there, and either may be higher for a while). Beams
// within 0.1 m of the map, at the estimate, do. Until a floor is named the
// search says why it cannot yet tell: no floor is localized yet, or another
// fits almost as well (floors that look the same from where the robot is),
// so that it is never confidently on the wrong floor.
//
// The verdict is the same a person would ask of several global searches
// run side by side; its figures on two floors of the bundled building are
// in docs/how-it-works/map.md, "A building's floors".
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/filter/prepared_map.h"
#include "pf_localization/core/sensor/scan_group.h"

namespace pf {

struct FloorSearchParams {
  int found_updates = 5;        // updates in a row the floor found fits best by the margin
  int fit_updates = 5;          // a floor's fit: averaged over this many updates
  double fit_distance = 0.1;    // m: a beam ending this close to an obstacle is explained
  double min_fit_margin = 0.1;  // the floor found explains this share more than every other
};

/// The share of the readings of `scans` that end within `distance` of an
/// obstacle of `field`, the robot at `robot` (0 without a reading).
double explainedShare(const DistanceField& field, const ScanGroup& scans, const Pose2& robot,
                      double distance);

/// Floor `floor`'s filter's seed in a search with `seed` (the filter's):
/// floor 0 takes it, each other floor its own stream (the seed moved by the
/// golden-ratio increment splitmix64 steps by), so that the floors' filters
/// draw independently, and the same seed gives the same search.
uint64_t floorSeed(uint64_t seed, std::size_t floor);

class FloorSearch {
 public:
  /// `maps[i]`: floor i's map, moved into floor i's filter (release()
  /// hands them back), `names[i]` its name in the verdict's reason (none:
  /// "floor i"). Each filter has `params`, with floorSeed(params.seed, i)
  /// for its seed; starts them globally. Throws std::invalid_argument for no
  /// map or invalid parameters.
  FloorSearch(const ParticleFilterParams& params, std::vector<PreparedMap> maps,
              std::vector<std::string> names = {}, FloorSearchParams search = {});

  /// One scan (or group of scans) at odometry pose `odom`: every floor's
  /// filter updates.
  void update(const Pose2& odom, const ScanGroup& scans);

  struct Verdict {
    std::optional<std::size_t> floor;  // the floor found; none: cannot yet tell
    std::string reason;                // why, in a few words
  };
  Verdict verdict() const;

  std::size_t floors() const { return filters_.size(); }
  /// Floor `floor`'s filter: its estimate is where the robot is if it is there.
  const ParticleFilter& filter(std::size_t floor) const { return *filters_[floor]; }

  /// The maps back, in floor order, with what their change layers learned;
  /// the search is over.
  std::vector<PreparedMap> release();

 private:
  // Floor `floor`'s name for the reasons.
  std::string nameOf(std::size_t floor) const;

  FloorSearchParams params_;
  std::vector<std::string> names_;
  std::vector<std::unique_ptr<ParticleFilter>> filters_;
  std::vector<int> lead_run_;              // per floor: updates in a row ahead by the margin
  std::vector<std::vector<double>> fits_;  // per floor: the last updates' explained shares
  // Floor `floor`'s fit: the mean of fits_[floor] (0 before an update).
  double fit(std::size_t floor) const;
  // The floor with the highest fit (the first of equals).
  std::size_t bestFit() const;
  // A floor other than `best` whose fit is within the margin of best's.
  std::optional<std::size_t> closeTo(std::size_t best) const;
};

}  // namespace pf

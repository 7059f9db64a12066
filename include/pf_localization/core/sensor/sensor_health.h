// How each of a robot's sensors is doing, for diagnostics and the state: its
// rate, the age of its latest scan, the share of that scan's beams that are
// readings and the share that fit the map at the estimate. A sensor is
// silent when its latest scan is older than kSilentAfter, and blocked when
// almost none of its beams are readings (a lidar with something stuck over
// it reads range_min on every beam, which laser_scan.h drops). Both say the
// sensor is missing, by name, within kSilentAfter of it stopping or being
// covered: the filter carries on with the others (scan_group.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace pf {

/// s without a scan after which a sensor is silent: ten periods of a 5 Hz
/// lidar, and the bound on naming a missing sensor.
constexpr double kSilentAfter = 2.0;
/// Below this share of readings among its beams a sensor is blocked. A
/// Neato loses 40 % of its beams to dropouts and blind sectors; a covered
/// lidar keeps none.
constexpr double kBlockedBelow = 0.05;

enum class SensorState { kWaiting, kOk, kSilent, kBlocked };

/// "waiting", "ok", "silent", "blocked".
const char* toString(SensorState state);

struct SensorStatus {
  std::string name;
  SensorState state = SensorState::kWaiting;  // no scan yet
  double rate_hz = 0.0;                       // scans per second, averaged over the last ones
  double age_s = 0.0;                         // since its latest scan
  double valid_share = 0.0;                   // of the latest scan's beams, readings
  double fit_share = 0.0;  // of those, ending near a mapped obstacle at the estimate
};

class SensorHealth {
 public:
  /// One entry per sensor, in the filter's sensor order.
  explicit SensorHealth(std::vector<std::string> names);

  /// One more sensor, after the others.
  void add(std::string name);
  std::size_t size() const { return names_.size(); }

  /// Sensor `sensor` gave a scan stamped `t` (s) with `beams` beams, `valid`
  /// of them readings, `fit` of those (0-1) near the map at the estimate.
  void observe(std::size_t sensor, double t, std::size_t beams, std::size_t valid, double fit);

  /// Every sensor's status at time `now` (s, the stamps' clock).
  std::vector<SensorStatus> status(double now) const;

  /// The missing sensors at `now`, "front_laser (silent 3.1 s), ..."; empty
  /// when none is.
  std::string missing(double now) const;

 private:
  struct Track {
    bool seen = false;
    double last = 0.0;
    double period = 0.0;  // s, exponentially averaged
    double valid_share = 0.0;
    double fit_share = 0.0;
  };
  std::vector<std::string> names_;
  std::vector<Track> tracks_;
};

}  // namespace pf

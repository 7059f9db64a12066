#include "pf_localization/ros/diagnostics/diagnostic_status.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace pf_ros {
namespace {

// As an ostream shows a double by default (%g, 6 digits), without building
// one: some twenty values are formatted after every update.
void add(diagnostic_msgs::DiagnosticStatus* status, const std::string& key, double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  diagnostic_msgs::KeyValue kv;
  kv.key = key;
  kv.value = text;
  status->values.push_back(kv);
}

// Counts in full (a double would show a million as 1e+06).
void add(diagnostic_msgs::DiagnosticStatus* status, const std::string& key, int value) {
  diagnostic_msgs::KeyValue kv;
  kv.key = key;
  kv.value = std::to_string(value);
  status->values.push_back(kv);
}

}  // namespace

diagnostic_msgs::DiagnosticStatus toDiagnosticStatus(const pf::ParticleFilter& filter,
                                                     const pf::UpdateReport& report,
                                                     const std::string& name,
                                                     int config_generation) {
  const pf::Confidence& c = filter.confidence();
  diagnostic_msgs::DiagnosticStatus status;
  status.name = name;
  status.hardware_id = "none";
  switch (c.state) {
    case pf::LocalizationState::kLocalized:
      status.level = diagnostic_msgs::DiagnosticStatus::OK;
      break;
    case pf::LocalizationState::kUncertain:
      status.level = diagnostic_msgs::DiagnosticStatus::WARN;
      break;
    default:
      status.level = diagnostic_msgs::DiagnosticStatus::ERROR;
  }
  status.message = std::string(pf::toString(c.state)) + ": " + c.reason;
  diagnostic_msgs::KeyValue state;
  state.key = "state";
  state.value = pf::toString(c.state);
  status.values.push_back(state);
  add(&status, "particles", static_cast<double>(filter.particles().size()));
  add(&status, "effective_sample_size", report.ess);
  add(&status, "mean_beam_likelihood", report.mean_beam_likelihood);
  add(&status, "hit_fraction", c.hit_fraction);
  add(&status, "std_x_m", c.std_x);
  add(&status, "std_y_m", c.std_y);
  add(&status, "std_yaw_deg", c.std_yaw * 180.0 / M_PI);
  add(&status, "clusters", static_cast<double>(filter.estimate().clusters.size()));
  add(&status, "rival_clusters", c.rivals);
  add(&status, "injected_particles", static_cast<double>(report.injected));
  add(&status, "tempering", report.tempering);
  // 0 but while a global localization's cloud is too sparse for laser_sigma_hit.
  add(&status, "search_smoothing_m", report.search_sigma);
  // Places elsewhere on the map the scan fits as well (look_alikes.h), and
  // the survivors recovery carried to one it fits clearly better.
  add(&status, "look_alike_places", static_cast<double>(report.look_alikes));
  add(&status, "moved_to_look_alikes", static_cast<double>(report.moved));
  add(&status, "beams_used", report.beams_used);
  // Left out: they see something that stepped up to the standing robot.
  add(&status, "beams_masked", report.beams_masked);
  // Left out too: they see where the world no longer matches the map, at a
  // tracked pose the rest of the scan agrees with (pf_map_changes).
  add(&status, "beams_changed", report.beams_changed);
  add(&status, "map_changed_share", report.map_changed_share);
  const pf::ParticleFilterParams& p = filter.params();
  add(&status, "config_generation", config_generation);
  add(&status, "max_particles", p.kld.max_particles);
  add(&status, "odom_alpha1", p.motion.alpha1);
  add(&status, "laser_sigma_hit", p.sensor.sigma_hit);
  return status;
}

void addSensors(diagnostic_msgs::DiagnosticStatus* status, const pf::SensorHealth& health,
                double now) {
  if (health.size() < 2) return;
  for (const pf::SensorStatus& s : health.status(now)) {
    char text[128];
    std::snprintf(text, sizeof text, "%s, %.1f Hz, %.2f s old, %.0f %% readings, %.0f %% fit",
                  pf::toString(s.state), s.rate_hz, s.age_s, 100.0 * s.valid_share,
                  100.0 * s.fit_share);
    diagnostic_msgs::KeyValue kv;
    kv.key = "sensor " + s.name;
    kv.value = text;
    status->values.push_back(kv);
  }
  const std::string missing = health.missing(now);
  if (missing.empty()) return;
  status->message += "; missing: " + missing;
  if (status->level < diagnostic_msgs::DiagnosticStatus::WARN) {
    status->level = diagnostic_msgs::DiagnosticStatus::WARN;
  }
}

void addHypotheses(diagnostic_msgs::DiagnosticStatus* status, const pf::Hypotheses& hypotheses) {
  add(status, "hypotheses", static_cast<int>(hypotheses.count));
  if (hypotheses.count < 2) return;
  std::string named = "; " + std::to_string(hypotheses.count) + " hypotheses: ";
  for (std::size_t k = 0; k < hypotheses.listed.size(); ++k) {
    const pf::Hypothesis& h = hypotheses.listed[k];
    char text[160];
    std::snprintf(text, sizeof text,
                  "x %.2f m, y %.2f m, yaw %.0f deg, %.0f %% of the weight, std %.2f m, %.2f m, "
                  "%.0f deg, %zu particles",
                  h.pose.x, h.pose.y, h.pose.yaw * 180.0 / M_PI, 100.0 * h.weight,
                  std::sqrt(h.covariance(0, 0)), std::sqrt(h.covariance(1, 1)),
                  std::sqrt(h.covariance(2, 2)) * 180.0 / M_PI, h.particles);
    diagnostic_msgs::KeyValue kv;
    kv.key = "hypothesis " + std::to_string(k + 1);
    kv.value = text;
    status->values.push_back(kv);
    if (k < kNamedHypotheses) {
      std::snprintf(text, sizeof text, "%s(%.2f, %.2f) %.0f %%", k > 0 ? ", " : "", h.pose.x,
                    h.pose.y, 100.0 * h.weight);
      named += text;
    }
  }
  if (hypotheses.count > kNamedHypotheses) named += ", ...";
  status->message += named;
}

void addMapChanges(diagnostic_msgs::DiagnosticStatus* status, const pf::MapChangeLayer* layer) {
  if (layer == nullptr) return;
  const pf::MapChangeLayer::Summary s = layer->summary();
  const auto mean = [](std::size_t scans, std::size_t cells) {
    return cells == 0 ? 0.0 : static_cast<double>(scans) / static_cast<double>(cells);
  };
  const double new_scans = mean(s.added_scans, s.added),
               gone_scans = mean(s.removed_scans, s.removed);
  char text[200];
  std::snprintf(text, sizeof text,
                "%zu cells new, %zu gone, of %zu seen, from %zu scans; each new one stopped the "
                "beams of %.1f scans on average, each gone one let through those of %.1f",
                s.added, s.removed, s.seen, layer->scans(), new_scans, gone_scans);
  diagnostic_msgs::KeyValue kv;
  kv.key = "map changes";
  kv.value = text;
  status->values.push_back(kv);
  add(status, "map_cells_seen", static_cast<double>(s.seen));
  add(status, "map_cells_new", static_cast<double>(s.added));
  add(status, "map_cells_gone", static_cast<double>(s.removed));
  add(status, "map_new_mean_scans", new_scans);
  add(status, "map_gone_mean_scans", gone_scans);
}

}  // namespace pf_ros

// The filter's confidence as a diagnostic_msgs/DiagnosticStatus: what pf_node
// publishes on /diagnostics and pf_status after every update.
#pragma once

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <cstddef>
#include <string>

#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/sensor/sensor_health.h"

namespace pf_ros {

/// OK when localized, WARN when uncertain, ERROR when lost; the message is the
/// state and its reason, the values every figure behind it, and a few of the
/// parameters in effect (max_particles, odom_alpha1, laser_sigma_hit) with
/// `config_generation`, the number of live changes accepted (ReconfigureServer),
/// so that a change can be seen to have reached the filter.
diagnostic_msgs::DiagnosticStatus toDiagnosticStatus(const pf::ParticleFilter& filter,
                                                     const pf::UpdateReport& report,
                                                     const std::string& name,
                                                     int config_generation = 0);

/// With several sensors: one value per sensor ("sensor NAME": its state,
/// rate, age, share of readings and of beams that fit) and, when one is
/// silent or blocked, its name in the message ("; missing: ...") and at
/// least WARN. `now` is the time of the stamps (s).
void addSensors(diagnostic_msgs::DiagnosticStatus* status, const pf::SensorHealth& health,
                double now);

// How many hypotheses the message names (a status line a monitor shows in
// one row); the values list every one.
constexpr std::size_t kNamedHypotheses = 4;

/// The hypotheses (pf_hypotheses): their count as a value and, when there
/// are several, each listed one as a value ("hypothesis K": pose, share of
/// the weight, spread, particles) and the first kNamedHypotheses in the
/// message ("; 2 hypotheses: (1.20, 7.60) 52 %, (11.20, 7.60) 47 %"), so
/// that a robot monitor shows where the robot may be.
void addHypotheses(diagnostic_msgs::DiagnosticStatus* status, const pf::Hypotheses& hypotheses);

/// What the layer of the map's changes (pf_map_changes) holds, from its
/// counts (map_change_layer.h): "map changes" in words, and as numbers its
/// cells seen, new (an obstacle the map lacks) and gone (a mapped obstacle
/// seen through), and the scans behind each new and each gone cell on
/// average (each has at least MapChangeLayer::kMinScans, and at least half of
/// the scans that reached it said so). Nothing without a map.
void addMapChanges(diagnostic_msgs::DiagnosticStatus* status, const pf::MapChangeLayer* layer);

}  // namespace pf_ros

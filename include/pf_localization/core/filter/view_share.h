// How much of a new view of the surroundings an update brings: the share of
// a full view, 0 to 1, that the parts tuned per update (the scan's evidence,
// the motion noise, the odometry-fault tracker, recovery's patience and
// averages) scale by.
//
// Every such part was set for an update per update_min_d or update_min_a at
// their defaults, amcl's 0.2 m and pi/6: one update, one new view. Scans
// taken closer together than that repeat most of the last one's evidence,
// and its errors with it (people, the map's walls), so n updates a view
// apart by 1/n each must add up to what one update a view apart does:
// the likelihood to the power 1/n, the motion variance shared out, the
// patience counted in views. With the defaults every update brings a whole
// view (its motion passed a threshold) and nothing changes. See
// docs/design.md, "Updates closer together than the defaults".
#pragma once

#include <cmath>

#include "pf_localization/core/util/pose2.h"

namespace pf {

/// A full view: the motion between two updates at the default thresholds
/// (update_min_d, update_min_a: amcl's, with which the per-update parts
/// were tuned).
constexpr double kViewDistance = 0.2;      // m
constexpr double kViewAngle = M_PI / 6.0;  // rad
/// Views summed from shares carry rounding (25 fifths exceed 5 by 1e-15):
/// counts of views compare with this much slack.
constexpr double kViewRounding = 1e-9;

/// Whether `views`, summed from shares, exceed `count` whole views.
inline bool moreViewsThan(double views, int count) { return views > count + kViewRounding; }

/// The share of a new view that odometry motion `delta` (between two
/// updates) brings: its travel over kViewDistance or its turn over
/// kViewAngle, whichever is larger, at most 1.
double newViewShare(const Pose2& delta);

/// The least share of a new view that an update let through by the
/// thresholds brings: update_min_d over kViewDistance or update_min_a over
/// kViewAngle, whichever is smaller, at most 1 (a whole view at amcl's
/// defaults, none with updates on every scan).
double leastUpdateShare(double update_min_d, double update_min_a);

}  // namespace pf

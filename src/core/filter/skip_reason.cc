#include "pf_localization/core/filter/skip_reason.h"

namespace pf {

const char* toString(SkipReason reason) {
  switch (reason) {
    case SkipReason::kNone:
      return "updated";
    case SkipReason::kNoMap:
      return "no map yet";
    case SkipReason::kNotInitialized:
      return "the filter is not initialised";
    case SkipReason::kOdometryNotFinite:
      return "the odometry pose is not finite";
    case SkipReason::kBadScan:
      return "bad scan";
    case SkipReason::kOdometryJumped:
      return "odometry jumped";
    case SkipReason::kNotMoved:
      return "not moved enough since the last update";
    case SkipReason::kNoValidBeam:
      return "no valid beam in the scan";
  }
  return "unknown skip reason";
}

}  // namespace pf

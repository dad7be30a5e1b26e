// Recorded joints outside the robot config's limits (docs/observations-format.md): the controller's
// reading is what happened, so such data is calibrated, with a warning naming the poses. Only commanding
// motion (`selfcal run`'s plan check and preflight) refuses poses beyond the limits.
#pragma once

#include <string>
#include <vector>

#include "observations/observation_set.h"

namespace selfcal {

// Reading tolerance: a value this far past a limit (rad) is on it.
inline constexpr double kJointLimitReadingToleranceRad = 1e-9;

// One sentence per pose with a joint outside the limits, naming the pose (id and 0-based index), every such
// joint (1-based), its value and the limits in degrees. Empty for a flange-pose set or when all are inside.
std::vector<std::string> PosesOutsideJointLimits(const ObservationSet& set);

}  // namespace selfcal

// Internal to the bundle module: the kinematic bundle adjustment's solve through Ceres' DENSE_SCHUR
// linear solver and trust-region Levenberg-Marquardt (one residual block per observation, the Huber loss
// as a Ceres loss function): what the bundle ran before kinematic_lm.h, kept as the reference the tests
// compare that solver with. Same inputs and summary as SolveKinematicBundle.
#pragma once

#include <vector>

#include "bundle/kinematic_lm.h"

namespace selfcal::bundle::internal {

LmSummary SolveWithCeres(const BundleData& data, const std::vector<int>& free, const std::vector<int>& free_intrinsics,
                         const LmOptions& options, BundleState* state);

}  // namespace selfcal::bundle::internal

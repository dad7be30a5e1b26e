// The dots the fit eliminated together: two dots joined by a yardstick share its residual, so the fit
// solved them as one block (bundle/bundle_problem.h), and what the identification images' errors did to
// them comes from that block, not from each dot's own images alone (heldout_reprojection.cc).
#pragma once

#include <map>
#include <vector>

#include <Eigen/Core>

#include "observations/observation_set.h"

namespace selfcal::calibration {

struct DotGroup {
  std::vector<int> ids;     // the dots, in the order of the blocks below
  Eigen::MatrixXd inverse;  // H_GG^-1, 3 x ids.size() square
};

// Groups of the dots in `hdd` (each dot's H_dd from its identification images, sigma = 1 px) joined by
// yardsticks with both ends among them: H_GG = blockdiag(H_dd) + sum over the group's yardsticks of w w^T,
// w = (u, -u) sigma_px / sigma_m on (dot_a, dot_b), u the unit vector from dot_b to dot_a (the linearised
// length residual, whitened as the fit whitened it). sigma_m <= 0: no groups.
std::vector<DotGroup> YardstickDotGroups(const std::vector<KnownDistance>& yardsticks, double sigma_m, double sigma_px,
                                         const std::map<int, Eigen::Matrix3d>& hdd,
                                         const std::map<int, Eigen::Vector3d>& dots);

}  // namespace selfcal::calibration

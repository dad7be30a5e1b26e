// Internal to calibration: the held-out test's screen of gross detection errors (heldout_reprojection.h,
// HeldOutReprojection::gross_errors), a piece of heldout_reprojection.cc.
//
// A detection is tested given the other detections of its pose (Baarda's test for one observation, in two
// dimensions): with C = sigma^2 I + G G^T + D D^T the covariance of the pose's residuals r (heldout_chi_square.h)
// and w = C^-1 r, t_k = w_k^T ((C^-1)_kk)^-1 w_k is chi-square with 2 degrees of freedom under the model. A pose
// error or a held parameter's tolerance moves a pose's dots together, and the other dots explain that; a
// misdetected corner moves one. (Tested against its own covariance alone, kvasios s1's 6 px corner hid in a
// held parameter's tolerance.) The worst beyond kGrossErrorChiSquare is left out and the pose's statistics are
// computed again without it (one outlier inflates its neighbours' statistics), until none is beyond or
// kMaxGrossErrorShare of the detections are out: a wrong model moves many and keeps all but a few in the test.
#pragma once

#include <vector>

#include "calibration/heldout_chi_square.h"
#include "calibration/heldout_reprojection.h"

namespace selfcal::calibration::internal {

// residuals, observed: one row per detection, pose by pose from first_row_of_pose (one entry per pose and
// one past the end); those left out move from both into *gross (in row order), and the poses' first rows
// follow.
void ScreenGrossErrors(double sigma, Residuals* residuals, std::vector<int>* first_row_of_pose,
                       std::vector<ObservedResidual>* observed, std::vector<ObservedResidual>* gross);

}  // namespace selfcal::calibration::internal

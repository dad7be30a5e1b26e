// The start of a flange-pose calibration: the hand-eye transform flange_from_cam from the images and
// the recorded flange motions, without any target (the scene's dots are unknown).
//
// For pairs (i, j) of identification poses, A = flange_i_from_flange_j (recorded) and
// B = cam_i_from_cam_j (the two-view estimate from the dots both images see: its rotation and the
// direction of its translation) satisfy A X = X B with X = flange_from_cam. Then:
//   rotation:    the rotation vectors obey a_A = R_X a_B, so R_X is the orthogonal Procrustes (Kabsch)
//                fit over every pair whose two rotation angles agree (the angle of a relative motion is
//                the same for the flange and the camera, whatever X is: a free consistency check that
//                throws out a pair with a wrong two-view rotation, e.g. the wrong one of a flat scene's
//                two solutions: of an ambiguous pair the solution whose angle matches is taken), refitted
//                without the pairs that leave large residuals;
//   translation: (R_A - I) t_X - s_ij R_X b_ij = -t_A with b_ij the unit translation of B and one unknown
//                length s_ij > 0 per pair: linear least squares in t_X and the s_ij (Tsai and Lenz's
//                equation with the camera's translation known only in direction).
// f_x: the median of the pairs' focal estimates where a pair observes it, else the prior.
// A flat target: when the dots of every view lie on one plane (twoview/planar_views.h: one homography
// per view from a reference view, whose decompositions agree on the plane's normal), the camera motions
// come from that multi-view solution instead of pair by pair: the plane's normal resolves each view's
// two-fold ambiguity, f_x comes from the views' agreement, and every pair's translation has a direction
// even where a two-view estimate would call it ambiguous. A pair falls back to its two-view estimate
// when the plane's motion does not turn by the flange's angle.
//
// Eye-to-hand (observations.robot.mount: a fixed camera, the dots on the flange) the roles swap: the camera
// moves against the flange's dots as flange_from_base moves against the base, so A = base_from_flange_i *
// base_from_flange_j^-1 (flange_from_base_i plays the flange pose), B is the same two-view motion, and
// X = base_from_cam, the fixed camera; everything else as above.
//
// Works on an ObservationSet only (its poses' base_from_flange); no files, no hardware.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "geometry/rigid3.h"
#include "observations/observation_set.h"
#include "twoview/planar_views.h"
#include "twoview/two_view.h"

namespace selfcal::calibration {

struct HandEyePair {
  std::string pose_a, pose_b;
  twoview::Outcome outcome = twoview::Outcome::kNotRun;
  double flange_angle_rad = 0;  // rotation angle of the recorded flange motion
  double camera_angle_rad = 0;  // of the two-view estimate of the camera motion
  bool used_for_rotation = false, used_for_translation = false;
  bool rival_chosen = false;    // an ambiguous pair's rival matched the flange's angle better
  bool from_plane = false;      // the camera motion is the flat-target solution's (outcome kSuccess)
};

struct HandEyeStartReport {
  bool ok = false;
  std::string message;
  Rigid3 flange_from_cam;  // eye-in-hand: the hand-eye transform X
  Rigid3 base_from_cam;    // eye-to-hand: X, the fixed camera (flange_from_cam then the identity)
  double fx_px = 0;
  bool fx_from_images = false;
  int rotation_pairs = 0, translation_pairs = 0;
  double rotation_rms_rad = 0;     // of |a_A - R_X a_B| over the rotation pairs used
  std::vector<HandEyePair> pairs;
  // The flat-target solution (reference: the identification pose with the most dots), when tried; used
  // when plane->ok.
  std::optional<twoview::PlanarViewsReport> plane;
  std::string plane_reference;  // its pose id
};

struct HandEyeStartOptions {
  twoview::TwoViewOptions two_view;
  int max_pairs = 200;                       // pairs tried, nearest poses in file order first
  double min_flange_angle_rad = 0.035;       // ~2 deg: below it a pair's rotation axis is noise
  double max_angle_mismatch_rad = 0.035;     // flange angle vs camera angle
  int min_matches = 8;
  bool try_plane = true;                     // try the flat-target solution first
  twoview::PlanarViewsOptions plane;
  double max_plane_transfer_px = 3.0;        // median homography residual beyond which the dots are no plane
};

HandEyeStartReport StartHandEye(const ObservationSet& observations, const HandEyeStartOptions& options);

// A joint-angle set's camera start from its images: the flange poses of the nominal kinematics at the
// recorded joints stand in for recorded flange poses (StartHandEye), and the hand-eye transform found becomes
// the camera correction of `rho` (robot.flange_from_cam, eye-to-hand robot.base_from_cam, times the
// correction; the nominal flange poses of an eye-to-hand set give the fixed camera), so that a wrong or absent
// camera mount in the robot description does not decide which minimum the bundle reaches. `rho` is left
// as it is when the start fails (report.ok false, with the reason).
HandEyeStartReport StartCameraFromImages(const ObservationSet& observations, const HandEyeStartOptions& options,
                                         Eigen::VectorXd* rho);

}  // namespace selfcal::calibration

// Several views of one plane (a flat target), solved together instead of pair by pair.
//
// The homography from a reference view to view j, in normalised coordinates at focal f_x,
//   H_j ~ R_j + t_j n^T,   n^T X = 1 for the plane's points X in the reference camera,
// has two physical decompositions (Faugeras), the two-fold planar ambiguity: one pair alone cannot say
// which is the camera's motion. But the plane's normal n in the reference camera is one vector for every
// view, so the solution whose normal agrees with the other views' is the physical one. With three or more
// views (two homographies) the agreement also fixes f_x: at a wrong focal length the decompositions'
// normals disagree (planar self-calibration for f_x alone, principal point and f_y / f_x known).
// Translations t_j are in units of the reference camera's distance to the plane, so every view's
// pose comes in one common scale.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "geometry/rigid3.h"

namespace selfcal::twoview {

struct PlanarViewsOptions {
  bool estimate_focal = true;
  double min_focal_ratio = 0.5;  // search range of f_x around camera.fx_px
  double max_focal_ratio = 2.0;
  int focal_steps = 120;         // log-spaced grid, then golden-section refinement
  int min_points = 8;            // dots a view must share with the reference
  double outlier_px = 3.0;       // transfer error beyond which a dot leaves a view's homography
  // A view counts as resolved when its rival's normal is at least this much farther from the consensus
  // than its chosen solution's.
  double resolve_margin_deg = 2.0;
  double max_normal_rms_deg = 5.0;  // consensus spread beyond which the views do not see one plane
};

struct PlanarView {
  bool ok = false;  // homography estimated and decomposed (the reference's entry: the identity)
  std::string message;
  int num_points = 0, num_inliers = 0;
  double transfer_rms_px = 0;  // of the inliers, at the final f_x, in image j
  Rigid3 cam_from_ref;         // chosen solution; translation in reference plane distances
  Eigen::Vector3d normal_in_ref = Eigen::Vector3d::Zero();
  bool has_rival = false;
  Rigid3 rival_cam_from_ref;
  Eigen::Vector3d rival_normal_in_ref = Eigen::Vector3d::Zero();
  double normal_error_rad = 0, rival_normal_error_rad = 0;  // angles to the consensus normal
  bool resolved = false;
};

struct PlanarViewsReport {
  bool ok = false;
  std::string message;
  int reference = -1;
  Eigen::Vector3d normal_in_ref = Eigen::Vector3d::Zero();  // consensus unit normal, towards the camera side
  double normal_rms_rad = 0;                                // of the chosen normals about it
  double fx_px = 0;
  bool fx_estimated = false;  // false: the prior (fewer than two views, or a flat cost)
  int views_ok = 0, views_resolved = 0;
  double median_transfer_rms_px = 0;
  std::vector<PlanarView> views;  // one per view given
};

// views[k]: dot id -> pixel of view k; `reference` indexes views.
PlanarViewsReport SolvePlanarViews(const CameraIntrinsics& camera, const std::vector<std::map<int, Eigen::Vector2d>>& views,
                                   int reference, const PlanarViewsOptions& options);

}  // namespace selfcal::twoview

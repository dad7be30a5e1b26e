// The images' own account of the camera motion: a bundle adjustment in which every image's camera pose
// is free (no robot, no flange poses), with the dots and the intrinsics asked for (f_x by default, any
// subset of the nine of camera/camera.h). Used to check recorded
// flange poses against the images with nothing assumed about the hand-eye transform: the rotation angle
// of a relative camera motion equals that of the matching flange motion whatever the hand-eye transform
// is, so the difference of the two angles, pair by pair, measures how far images and flange poses agree.
//
// Gauge: the first pose's camera is held; the scale (invisible) is held softly by the distance between
// the first two cameras at the start (a stiff residual); rotations are unaffected by either.
// Planar scenes: started from a consistent multi-view solution (e.g. the hand-eye bundle's), the
// two-fold ambiguity of a flat scene's two-view poses does not arise: all views share one plane.
//
// Residuals as in bundle_adjustment.h (whitened by sigma), Huber while outliers are screened by the
// same 4-sigma rule, a plain least-squares refit on the rest. Deterministic, single-threaded.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "geometry/rigid3.h"
#include "observations/observation_set.h"

namespace selfcal::bundle {

struct FreeCameraOptions {
  IntrinsicsMask intrinsics = kFocalLengthOnly;  // estimated; the others held at observations.camera's
  double huber_px = 2.0;
  double screen_sigma = 4.0;
  int max_iterations = 200;
};

struct FreeCameraReport {
  bool ok = false;
  std::string message;
  std::vector<int> poses;              // indices into observations.poses, in order
  std::vector<Rigid3> base_from_cam;   // per entry of poses, in the start's frame and scale (the dots' frame: PointsFromCam)
  IntrinsicsVector intrinsics{};       // every intrinsic, held ones at the start
  int num_observations = 0, num_removed = 0;
  double rms_reprojection_px = 0;
};

// Every pose of `observations` with a start camera in `base_from_cam_start` (indexed like
// observations.poses; poses without an entry in `use` are left out) and every dot of `dots_start` seen
// by at least two of them; the intrinsics start at observations.camera's.
FreeCameraReport RunFreeCameraBundle(const ObservationSet& observations, const std::vector<Rigid3>& base_from_cam_start,
                                     const std::vector<bool>& use, const std::map<int, Eigen::Vector3d>& dots_start,
                                     const FreeCameraOptions& options);

}  // namespace selfcal::bundle

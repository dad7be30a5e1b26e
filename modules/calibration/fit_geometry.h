// What a picture of the bundle stage's fit needs beyond its figures (report/ plots it in report.html):
// where the calibrated model puts the camera at every pose, and every identification detection beside
// the bundle's prediction of it at the solution.
//
// The camera poses: base_from_cam = BaseFromCamAt(observations.robot, bundle.rho, pose) (the base frame
// of the bundle's gauge, the frame of bundle.dots_in_base). The residuals: each dot of
// bundle.dots_in_base projected into each identification pose that saw it and whose observation the
// screen kept (bundle.removed left out), with the bundle's f_x and k1: the observations of the final fit,
// so their number is bundle.num_observations and their RMS bundle.rms_reprojection_px.
//
// Works on an ObservationSet only: no files, no hardware, no truth.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "bundle/bundle_adjustment.h"
#include "calibration/heldout_reprojection.h"
#include "geometry/rigid3.h"
#include "observations/observation_set.h"

namespace selfcal::calibration {

struct CameraPose {
  std::string pose_id;
  PoseRole role = PoseRole::kIdentification;
  Rigid3 base_from_cam;  // m, the calibrated model at this pose's joints (or flange pose)
};

struct FitGeometry {
  std::vector<CameraPose> camera_poses;                    // every pose, in file order
  std::vector<ObservedResidual> identification_residuals;  // the final fit's observations, pose by pose
};

// Empty when the bundle did not solve (no dots: it stopped before, e.g. kDegenerate, and its rho is its
// start), or gave no full rho or no positive f_x. An unconverged solve has its geometry (where it stopped).
FitGeometry FitGeometryOf(const ObservationSet& observations, const bundle::BundleReport& bundle);

// The median distance (m) from the identification cameras of `geometry` (FitGeometryOf of the same
// observations) to the dots of `dots_in_base` they see: the scene's depth, which turns an image error
// into one at the scene (depth / f_x per px). NaN without such a camera and dot.
double MedianCameraToDotDistance(const ObservationSet& observations, const FitGeometry& geometry,
                                 const std::map<int, Eigen::Vector3d>& dots_in_base);

}  // namespace selfcal::calibration

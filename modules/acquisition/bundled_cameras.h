// The session's own account of its cameras, for naming at the end of a session (late_naming.h,
// seen_once.h): every accepted sample's camera and the focal length from a bundle adjustment in which
// each camera is free (bundle/free_camera_bundle.h), started from the cameras resected on the nominal
// model's points (dot_prediction.h, SampleCameras). Resecting each camera on points that were
// triangulated from cameras that are themselves a little off converges slowly (twenty rounds still
// left 1.3 px between the rays of a dot near the camera), and no pose absorbs an error of f_x; the joint
// solve leaves the rays as far apart as the noise. Nothing here reads a file or touches a device.
#pragma once

#include <string>
#include <vector>

#include "acquisition/dot_prediction.h"

namespace selfcal::acquisition {

struct BundledCameras {
  bool ok = false;
  std::string message;                // the solve's, or why there is no solve
  std::vector<Rigid3> base_from_cams;  // per sample, in the first sample's nominal frame
  double fx_px = 0;                    // estimated
  double rms_reprojection_px = 0;
};

BundledCameras BundleSampleCameras(const PredictionModel& model, const std::vector<ViewedSample>& samples,
                                   const DotPredictionOptions& options);

// `samples` with the bundle's cameras given (ViewedSample::base_from_cam) and `model` with its f_x, when
// the bundle succeeded; unchanged otherwise.
void UseBundledCameras(const BundledCameras& bundled, PredictionModel* model, std::vector<ViewedSample>* samples);

}  // namespace selfcal::acquisition

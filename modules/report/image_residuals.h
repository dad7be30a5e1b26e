// image_residuals.csv: one row per image of a calibration, for a person or a script that should not have to
// parse report.json (docs/report-format.md, "image_residuals.csv"). `calibrate` (and `simulate`) write it
// beside report.json on every run.
//
// Columns, one row per pose in the observations' order:
//   pose, role                    the pose id and identification / verification
//   detections                    dots detected in the image
//   used                          residuals of this image: an identification image's observations in the
//                                 bundle's final fit (methods.bundle.plot_data.identification_residuals), a
//                                 verification image's predicted detections (heldout_residuals)
//   screened_out                  detections left out as gross errors (the fit's screen,
//                                 removed_observations; the held-out test's gross errors)
//   rms_px                        sqrt(mean |r|^2) over the used residuals (2-D, as rms_reprojection_px)
//   max_residual_px, max_residual_dot   the largest |r| of the image, screened-out detections included
//                                 (|r| at the final solution), and its dot id
//   camera_translation_error_mm, camera_rotation_error_deg   the image's own camera pose (from the images
//                                 alone, hand_eye.image_motions.camera_poses_from_images) against the model's
//                                 camera pose (flange pose times hand-eye transform)
// A figure that was not computed is an empty cell: no bundle (the paper's method, or a stop before the
// solve), no used residual, or no free-camera poses (a joint-angle set, or a flange set whose image check did
// not solve). Numbers with 6 decimals; a pose id with a comma, quote or line break is quoted (RFC 4180).
#pragma once

#include <string>

#include "calibration/calibrate.h"
#include "observations/observation_set.h"

namespace selfcal::report {

inline constexpr const char* kImageResidualsHeader =
    "pose,role,detections,used,screened_out,rms_px,max_residual_px,max_residual_dot,camera_translation_error_mm,"
    "camera_rotation_error_deg";

// The file's text, header line first, every line ending in "\n".
std::string ImageResidualsCsv(const ObservationSet& observations, const calibration::CalibrationReport& report);

}  // namespace selfcal::report

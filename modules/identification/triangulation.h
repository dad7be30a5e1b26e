// Scale and verification geometry (paper section 3.2 eq. (21), section 4.1 steps 4 and 5).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "camera/camera.h"
#include "geometry/rigid3.h"

namespace selfcal::identification {

// Eq. (21): t_i = (||tbar_i|| / ||tbar_1||) * k1 * direction_i for every pose measurement i, where tbar
// are the nominal relative translations and k1 the scale of the first one. directions are unit vectors.
std::vector<Eigen::Vector3d> ScaleByNominalRatios(const std::vector<Eigen::Vector3d>& directions,
                                                  const std::vector<Eigen::Vector3d>& nominal_translations,
                                                  double k1);

// One point seen in several views: camera poses in a common frame and the pixel in each.
struct PointTrack {
  std::vector<Rigid3> base_from_cam;
  std::vector<Eigen::Vector2d> pixels;
};

struct TriangulationResult {
  bool ok = false;
  std::string message;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // in the common frame
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // from sigma_px, first order
  double rms_reprojection_px = 0;
};

// Linear (DLT) then Gauss-Newton on the reprojection error, >= 2 views, the point in front of every
// camera. Covariance from the Gauss-Newton normal matrix with pixel std sigma_px.
TriangulationResult TriangulatePoint(const CameraIntrinsics& camera, double fx_px, const PointTrack& track,
                                     double sigma_px);

struct YardstickView {
  double length_m = 0;         // known
  PointTrack end_a, end_b;
};

struct ScaleEstimate {
  bool ok = false;
  std::string message;         // S1/S3 refusals in words
  double scale = 1;            // multiply every length of the model by this
  double scale_sigma = 0;      // first-order, from the triangulation covariances
  std::vector<double> measured_lengths_m;  // per yardstick, before scaling
  std::vector<double> per_yardstick_scale;
};

// Least squares over the yardsticks: L_j = s * l_j (weighted by 1/var(l_j)), with the propagated std
// of s. Refuses (ok = false) when a yardstick lacks two views of either end (S1) or the relative std of
// s exceeds max_relative_sigma (S3).
ScaleEstimate EstimateYardstickScale(const CameraIntrinsics& camera, double fx_px,
                                     const std::vector<YardstickView>& yardsticks, double sigma_px,
                                     double max_relative_sigma = 0.05);

}  // namespace selfcal::identification

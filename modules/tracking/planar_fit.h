// Plane-to-plane maps between two 2-D point sets, the geometric consistency checks of the tracker (D4) and
// of the grid identity (D5).
//
// `to_from_from` maps homogeneous points of the first set to the second: to ~ H (from_x, from_y, 1). Units
// are those of the inputs (pixels, or grid cells). Residuals are transfer errors in the `to` set:
// |to - Map(H, from)|.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/status.h"

namespace selfcal::tracking {

// Maps p by H; NaN when p maps to infinity (|w| < 1e-12).
Eigen::Vector2d MapPoint(const Eigen::Matrix3d& to_from_from, const Eigen::Vector2d& p);

// Least-squares homography (Hartley-normalised DLT) from >= 4 correspondences, scaled so that H(2,2) = 1
// when possible (unit Frobenius norm otherwise). nullopt when fewer than 4 points, sizes differ, any
// point is not finite, or the points are degenerate (a 2-D null space, e.g. three of four collinear).
std::optional<Eigen::Matrix3d> FitHomography(const std::vector<Eigen::Vector2d>& from,
                                             const std::vector<Eigen::Vector2d>& to);

// Least-squares affine map (last row 0 0 1) from >= 3 non-collinear correspondences.
std::optional<Eigen::Matrix3d> FitAffine(const std::vector<Eigen::Vector2d>& from,
                                         const std::vector<Eigen::Vector2d>& to);

enum class PlanarModel { kAffine, kHomography };
const char* PlanarModelName(PlanarModel model);

struct RobustPlanarFitOptions {
  PlanarModel model = PlanarModel::kHomography;
  double inlier_threshold = 2.0;   // transfer error, in the units of `to`
  int iterations = 200;            // at most this many random minimal samples...
  double confidence = 0.999;       // ...fewer once a sample without outliers was drawn with this probability
  double min_inlier_fraction = 0.5;  // below it the fit is refused (too many outliers to trust it)
  std::uint64_t seed = 1;          // std::mt19937_64 seed: the same input gives the same result
  Status Validate() const;
};

struct RobustPlanarFit {
  bool ok = false;
  std::string message;             // why not, when !ok
  Eigen::Matrix3d to_from_from = Eigen::Matrix3d::Identity();
  std::vector<double> residuals;   // per correspondence, NaN where it maps to infinity
  std::vector<bool> inliers;       // residual <= inlier_threshold
  int inlier_count = 0;
};

// RANSAC over minimal samples (4 for a homography, 3 for an affine map; the usual adaptive count
// log(1 - confidence) / log(1 - w^s) from the best inlier fraction w so far, capped by `iterations`), then
// least squares on the largest inlier set, re-scored twice. Throws InvalidArgument on invalid options or sizes that differ.
RobustPlanarFit FitPlanarRobust(const RobustPlanarFitOptions& options, const std::vector<Eigen::Vector2d>& from,
                                const std::vector<Eigen::Vector2d>& to);

}  // namespace selfcal::tracking

#include "bundle/free_camera_bundle.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "bundle/small_solve.h"
#include "camera/camera.h"

namespace selfcal::bundle {

namespace {

struct Reprojection {
  Reprojection(Eigen::Vector2d pixel, double sigma) : pixel(std::move(pixel)), inv_sigma(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* cam, const T* dot, const T* intrinsics, T* residual) const {
    T p[3];
    ceres::AngleAxisRotatePoint(cam, dot, p);
    const Vec3T<T> in_cam(p[0] + cam[3], p[1] + cam[4], p[2] + cam[5]);
    return internal::WhitenedReprojection<T>(intrinsics, in_cam, pixel, inv_sigma, residual);
  }
  Eigen::Vector2d pixel;
  double inv_sigma;
};

// The distance between two camera centres (centre = -R^T t), held at `length` (the scale gauge).
struct CentreDistance {
  CentreDistance(double length, double sigma) : length(length), inv_sigma(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    T ca[3], cb[3];
    const T minus_a[3] = {-a[0], -a[1], -a[2]}, minus_b[3] = {-b[0], -b[1], -b[2]};
    ceres::AngleAxisRotatePoint(minus_a, a + 3, ca);
    ceres::AngleAxisRotatePoint(minus_b, b + 3, cb);
    T d2 = T(0);
    for (int k = 0; k < 3; ++k) d2 += (ca[k] - cb[k]) * (ca[k] - cb[k]);
    residual[0] = (sqrt(d2) - T(length)) * T(inv_sigma);
    return true;
  }
  double length, inv_sigma;
};

struct Obs {
  int camera = -1;  // index into the camera blocks
  int dot = -1;     // dot id
  Eigen::Vector2d pixel;
};

std::array<double, 6> CameraBlock(const Rigid3& base_from_cam) {
  const Rigid3 cam_from_base = base_from_cam.Inverse();
  std::array<double, 6> block;
  ceres::RotationMatrixToAngleAxis(ceres::ColumnMajorAdapter3x3(cam_from_base.rotation.data()), block.data());
  for (int k = 0; k < 3; ++k) block[3 + k] = cam_from_base.translation[k];
  return block;
}

Rigid3 FromBlock(const std::array<double, 6>& block) {
  Eigen::Matrix3d r;
  ceres::AngleAxisToRotationMatrix(block.data(), ceres::ColumnMajorAdapter3x3(r.data()));
  return Rigid3(r, Eigen::Vector3d(block[3], block[4], block[5])).Inverse();
}

// Reprojection error |r| (px) of one observation at the current blocks; NaN behind the camera.
double ErrorPx(const std::array<double, 6>& cam, const Eigen::Vector3d& dot, const IntrinsicsVector& intrinsics,
               const Eigen::Vector2d& pixel) {
  Reprojection f(pixel, 1.0);
  double r[2];
  if (!f(cam.data(), dot.data(), intrinsics.data(), r)) return NAN;
  return std::hypot(r[0], r[1]);
}

}  // namespace

FreeCameraReport RunFreeCameraBundle(const ObservationSet& obs, const std::vector<Rigid3>& base_from_cam_start,
                                     const std::vector<bool>& use, const std::map<int, Eigen::Vector3d>& dots_start,
                                     const FreeCameraOptions& options) {
  FreeCameraReport report;
  std::vector<std::array<double, 6>> cams;
  for (size_t p = 0; p < obs.poses.size() && p < use.size() && p < base_from_cam_start.size(); ++p) {
    if (!use[p]) continue;
    report.poses.push_back(static_cast<int>(p));
    cams.push_back(CameraBlock(base_from_cam_start[p]));
  }
  if (cams.size() < 2) {
    report.message = "fewer than two poses";
    return report;
  }
  std::map<int, Eigen::Vector3d> dots;
  std::map<int, int> views;
  std::vector<Obs> all;
  for (size_t c = 0; c < report.poses.size(); ++c) {
    for (const auto& [id, pixel] : obs.poses[report.poses[c]].dots_px) {
      if (!dots_start.count(id)) continue;
      all.push_back({static_cast<int>(c), id, pixel});
      ++views[id];
    }
  }
  for (const auto& [id, n] : views) {
    if (n >= 2) dots[id] = dots_start.at(id);
  }
  const double sigma = obs.pixel_noise_px;
  IntrinsicsVector intrinsics = IntrinsicsOf(obs.camera);
  const double centre_distance = (base_from_cam_start[report.poses[0]].translation -
                                  base_from_cam_start[report.poses[1]].translation).norm();
  std::vector<bool> keep(all.size(), true);
  ceres::Solver::Summary summary;
  ceres::HuberLoss huber(options.huber_px / sigma);
  for (int round = 0; round < 2; ++round) {
    ceres::Problem problem;
    for (size_t k = 0; k < all.size(); ++k) {
      if (!keep[k] || !dots.count(all[k].dot)) continue;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Reprojection, 2, 6, 3, kNumIntrinsics>(
                                   new Reprojection(all[k].pixel, sigma)),
                               round == 0 ? new ceres::LossFunctionWrapper(&huber, ceres::DO_NOT_TAKE_OWNERSHIP) : nullptr,
                               cams[all[k].camera].data(), dots[all[k].dot].data(), intrinsics.data());
    }
    if (!problem.HasParameterBlock(cams[0].data()) || !problem.HasParameterBlock(cams[1].data())) {
      report.message = "the first two poses share no dot with the others";
      return report;
    }
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CentreDistance, 1, 6, 6>(
                                 new CentreDistance(centre_distance, 1e-6 * std::max(centre_distance, 1e-3))),
                             nullptr, cams[0].data(), cams[1].data());
    problem.SetParameterBlockConstant(cams[0].data());
    summary = internal::SolveWithIntrinsics(&problem, intrinsics.data(), options.intrinsics, options.max_iterations);
    if (internal::SolverFailed(summary, &report.message)) return report;
    // Screen against the robust solution: |r| beyond screen_sigma robust sigmas (never below the noise).
    std::vector<double> errors;
    for (const Obs& o : all) {
      errors.push_back(dots.count(o.dot) ? ErrorPx(cams[o.camera], dots[o.dot], intrinsics, o.pixel) : NAN);
    }
    const double limit = internal::ScreenLimit(errors, sigma, options.screen_sigma);
    if (!std::isfinite(limit)) break;
    if (round == 0) {
      for (size_t k = 0; k < all.size(); ++k) keep[k] = errors[k] <= limit;
    } else {
      double sum2 = 0;
      report.num_observations = 0;
      for (size_t k = 0; k < all.size(); ++k) {
        if (!keep[k] || !std::isfinite(errors[k])) continue;
        sum2 += errors[k] * errors[k];
        ++report.num_observations;
      }
      report.rms_reprojection_px = report.num_observations > 0 ? std::sqrt(sum2 / report.num_observations) : 0.0;
    }
  }
  report.num_removed = static_cast<int>(std::count(keep.begin(), keep.end(), false));
  for (const auto& block : cams) report.base_from_cam.push_back(FromBlock(block));
  report.intrinsics = intrinsics;
  report.ok = summary.termination_type == ceres::CONVERGENCE || summary.termination_type == ceres::NO_CONVERGENCE;
  std::ostringstream msg;
  msg << ceres::TerminationTypeToString(summary.termination_type) << ": " << report.num_observations
      << " observations of " << dots.size() << " dots in " << cams.size() << " images, " << report.num_removed
      << " removed by the screen, RMS " << report.rms_reprojection_px << " px";
  report.message = msg.str();
  return report;
}

}  // namespace selfcal::bundle

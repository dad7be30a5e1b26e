// A synthetic cell with a known truth for the prediction tests (dot_prediction_test.cc,
// late_naming_test.cc): a PUMA 560 looking at 60 dots 0.4-0.8 m away from six nearby poses, with
// hidden kinematic errors of the given sizes.
#pragma once

#include <map>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "acquisition/dot_prediction.h"
#include "support/test_robots.h"

namespace selfcal::acquisition {

struct Cell {
  PredictionModel nominal;
  Eigen::VectorXd rho_true;
  std::vector<Eigen::Vector3d> dots_in_base;
  std::vector<Eigen::VectorXd> joints;
};

inline Cell MakeCell(double length_error_m, double angle_error_rad, std::uint64_t seed) {
  Cell c;
  c.nominal.robot = testing::Puma560();
  c.nominal.camera = CameraIntrinsics();
  c.nominal.pixel_noise_px = 0.2;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0, 1);
  const KinematicParameters params(c.nominal.robot.num_joints());
  c.rho_true = KinematicParameters::Nominal(c.nominal.robot);
  for (int i = 0; i < params.size(); ++i) {
    c.rho_true[i] += (params.kind(i) == ParameterKind::kLength ? length_error_m : angle_error_rad) * n01(rng);
  }
  Eigen::VectorXd q0(6);
  q0 << 0.2, 0.6, -2.4, 0.1, 0.7, 0.3;
  for (int k = 0; k < 6; ++k) {
    Eigen::VectorXd q = q0;
    for (int j = 0; j < 6; ++j) q[j] += 0.03 * std::sin(1.7 * k + j);
    c.joints.push_back(q);
  }
  // Dots in front of the first camera, across its view.
  const Rigid3 base_from_cam = BaseFromCam(c.nominal.robot, c.rho_true, c.joints[0]);
  std::uniform_real_distribution<double> u(120, 520), v(100, 380), depth(0.4, 0.8);
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector2d xy = PixelToNormalized(c.nominal.camera, c.nominal.camera.fx_px, {u(rng), v(rng)});
    c.dots_in_base.push_back(base_from_cam * (depth(rng) * Eigen::Vector3d(xy.x(), xy.y(), 1.0)));
  }
  return c;
}

// The true pixels of every dot at joints q, with pixel noise.
inline std::map<int, Eigen::Vector2d> Observe(const Cell& c, const Eigen::VectorXd& q, std::mt19937_64* rng) {
  std::normal_distribution<double> noise(0, c.nominal.pixel_noise_px);
  const Rigid3 cam_from_base = BaseFromCam(c.nominal.robot, c.rho_true, q).Inverse();
  std::map<int, Eigen::Vector2d> px;
  for (size_t i = 0; i < c.dots_in_base.size(); ++i) {
    const auto uv = Project(c.nominal.camera, cam_from_base * c.dots_in_base[i]);
    if (uv && InImage(c.nominal.camera, *uv, 5)) px[static_cast<int>(i)] = *uv + Eigen::Vector2d(noise(*rng), noise(*rng));
  }
  return px;
}

}  // namespace selfcal::acquisition

// Test-only helpers shared by the two-view tests: the synthetic two-camera scene, noise, pose errors
// and default options.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "twoview/two_view.h"

namespace selfcal::twoview::test_scene {

// ---- Synthetic scene ------------------------------------------------------------------------------
//
//   cam1 at the origin looking along +z; 80 points in a 0.3 x 0.25 x 0.2 m box centred 0.75 m ahead;
//   cam2 displaced by `centre2` and aimed at `target2`, which is off cam1's optical axis so that the two
//   axes do not intersect (f_x observable), with an extra roll about its own axis.

inline CameraIntrinsics TestCamera() {
  CameraIntrinsics camera;
  camera.width_px = 640;
  camera.height_px = 480;
  camera.fx_px = 1000;
  camera.mu = 1;
  camera.cx_px = 319.5;
  camera.cy_px = 239.5;
  return camera;
}

struct SceneSpec {
  CameraIntrinsics camera = TestCamera();
  Eigen::Vector3d centre2{0.2, 0.03, 0.05};
  Eigen::Vector3d target2{-0.02, 0.1, 0.75};
  double roll2_rad = 0.1;
  int num_points = 80;
  bool planar = false;
  Eigen::Vector3d plane_normal{0.25, -0.15, -1.0};  // towards cam1, tilted
  bool pure_rotation = false;                       // centre2 ignored, cam2 at the origin
  Eigen::Vector3d box_centre{0, 0, 0.75};           // of the non-planar points, in cam1
  Eigen::Vector3d box_half{0.15, 0.125, 0.1};       // half extents of that box
};

struct Scene {
  CameraIntrinsics camera;
  Rigid3 cam2_from_cam1;
  std::vector<Eigen::Vector3d> points;  // in cam1
  std::vector<Eigen::Vector2d> pixels1, pixels2;
};

// cam_from_world of a camera at `centre` looking at `target` (image y roughly along world y).
inline Rigid3 LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target, double roll_rad) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_cam;
  world_from_cam << x, y, z;
  world_from_cam = world_from_cam * RotZ(roll_rad);
  const Eigen::Matrix3d r = world_from_cam.transpose();
  return Rigid3(r, -(r * centre));
}

inline Scene MakeScene(const SceneSpec& spec, std::mt19937_64* rng) {
  Scene scene;
  scene.camera = spec.camera;
  const Eigen::Vector3d centre2 = spec.pure_rotation ? Eigen::Vector3d::Zero() : spec.centre2;
  scene.cam2_from_cam1 = LookAt(centre2, spec.target2, spec.roll2_rad);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Eigen::Vector3d centre(0, 0, 0.75);
  const Eigen::Vector3d n = spec.plane_normal.normalized();
  const Eigen::Vector3d e1 = n.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d e2 = n.cross(e1);
  int attempts = 0;
  while (static_cast<int>(scene.points.size()) < spec.num_points) {
    EXPECT_LT(++attempts, 100 * spec.num_points) << "scene generator cannot fill the view";
    if (attempts >= 100 * spec.num_points) break;
    const Eigen::Vector3d p = spec.planar
                                  ? Eigen::Vector3d(centre + 0.15 * unit(*rng) * e1 + 0.12 * unit(*rng) * e2)
                                  : Eigen::Vector3d(spec.box_centre + Eigen::Vector3d(spec.box_half.x() * unit(*rng),
                                                                                      spec.box_half.y() * unit(*rng),
                                                                                      spec.box_half.z() * unit(*rng)));
    const auto uv1 = Project(scene.camera, p);
    const auto uv2 = Project(scene.camera, scene.cam2_from_cam1 * p);
    if (!uv1 || !uv2 || !InImage(scene.camera, *uv1, 5) || !InImage(scene.camera, *uv2, 5)) continue;
    scene.points.push_back(p);
    scene.pixels1.push_back(*uv1);
    scene.pixels2.push_back(*uv2);
  }
  return scene;
}

inline void AddNoise(double sigma_px, std::mt19937_64* rng, std::vector<Eigen::Vector2d>* pixels) {
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (Eigen::Vector2d& uv : *pixels) uv += Eigen::Vector2d(noise(*rng), noise(*rng));
}

inline double RotationError(const Eigen::Matrix3d& truth, const Eigen::Matrix3d& estimate) {
  return RotationAngle(truth.transpose() * estimate);
}

inline double DirectionError(const Eigen::Vector3d& truth, const Eigen::Vector3d& estimate) {
  const Eigen::Vector3d a = truth.normalized(), b = estimate.normalized();
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

inline TwoViewOptions Options(bool estimate_focal = true) {
  TwoViewOptions options;
  options.estimate_focal = estimate_focal;
  return options;
}

}  // namespace selfcal::twoview::test_scene

// Test-only helpers shared by the bundle tests: the simulated PUMA world of the paper pipeline's tests,
// gauge-invariant pose errors, and a flat-sheet variant of a world.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::bundle::testing {

inline sim::SimResult World(double noise_px, uint64_t world_seed = 1, uint64_t noise_seed = 1) {
  return selfcal::testing::PumaArcWorld(noise_px, world_seed, noise_seed);
}

inline BundleTruth Truth(const sim::SimResult& world) {
  BundleTruth truth;
  truth.rho = world.truth.rho_true;
  truth.camera = world.truth.camera_true;
  for (size_t d = 0; d < world.truth.dots_in_base.size(); ++d) truth.dots_in_base[static_cast<int>(d)] = world.truth.dots_in_base[d];
  return truth;
}

// Gauge-invariant: the predicted cam_ref_from_cam_v (ref = first identification pose) of every
// verification pose against the truth.
struct PoseErrors {
  std::vector<double> position_m, rotation_rad;
  double MaxPosition() const { return position_m.empty() ? 0 : *std::max_element(position_m.begin(), position_m.end()); }
  double MaxRotation() const { return rotation_rad.empty() ? 0 : *std::max_element(rotation_rad.begin(), rotation_rad.end()); }
};
inline PoseErrors VerificationPoseErrors(const sim::SimResult& world, const ObservationSet& obs, const RobotModel& robot,
                                         const Eigen::VectorXd& rho) {
  PoseErrors out;
  const int ref = obs.PosesWithRole(PoseRole::kIdentification).front();
  const Rigid3 model_ref_from_base = BaseFromCam(robot, rho, obs.poses[ref].joints_rad).Inverse();
  const Rigid3 true_ref_from_base = world.truth.base_from_cam[ref].Inverse();
  for (int v : obs.PosesWithRole(PoseRole::kVerification)) {
    const Rigid3 model = model_ref_from_base * BaseFromCam(robot, rho, obs.poses[v].joints_rad);
    const Rigid3 truth = true_ref_from_base * world.truth.base_from_cam[v];
    const PoseDifference d = ComparePoses(model, truth);
    out.position_m.push_back(d.position_m);
    out.rotation_rad.push_back(d.rotation_rad);
  }
  return out;
}

// The world's dots moved onto the horizontal plane z = mean z (base frame), re-observed with the true
// cameras and Gaussian noise; dots leaving an image (10 px margin) are not seen there. The yardstick and
// check distances take the flattened lengths. *flat_dots receives the new truth.
inline ObservationSet FlatSheet(const sim::SimResult& world, double noise_px, uint64_t seed,
                                std::map<int, Eigen::Vector3d>* flat_dots) {
  double z = 0;
  for (const Eigen::Vector3d& p : world.truth.dots_in_base) z += p.z();
  z /= static_cast<double>(world.truth.dots_in_base.size());
  std::vector<Eigen::Vector3d> dots;
  flat_dots->clear();
  for (size_t d = 0; d < world.truth.dots_in_base.size(); ++d) {
    Eigen::Vector3d p = world.truth.dots_in_base[d];
    p.z() = z;
    dots.push_back(p);
    (*flat_dots)[static_cast<int>(d)] = p;
  }
  ObservationSet obs = world.observations;
  for (KnownDistance& k : obs.yardsticks) k.length_m = (dots[k.dot_a] - dots[k.dot_b]).norm();
  for (KnownDistance& k : obs.check_distances) k.length_m = (dots[k.dot_a] - dots[k.dot_b]).norm();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  obs.pixel_noise_px = noise_px > 0 ? noise_px : 0.1;
  for (size_t i = 0; i < obs.poses.size(); ++i) {
    obs.poses[i].dots_px.clear();
    const Rigid3 cam_from_base = world.truth.base_from_cam[i].Inverse();
    for (size_t d = 0; d < dots.size(); ++d) {
      const auto uv = Project(world.truth.camera_true, cam_from_base * dots[d]);
      const Eigen::Vector2d n(noise(rng), noise(rng));
      if (!uv || !InImage(world.truth.camera_true, *uv, 10.0)) continue;
      obs.poses[i].dots_px[static_cast<int>(d)] = *uv + noise_px * n;
    }
  }
  return obs;
}

}  // namespace selfcal::bundle::testing

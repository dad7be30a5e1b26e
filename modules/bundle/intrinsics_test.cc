// The bundle's intrinsics chosen by name: the names and groups, the recovery of freed intrinsics against
// the simulator's truth (exact without noise, within the reported sigmas with it), and a mask the poses
// cannot support refused by the gauge check, naming the intrinsic.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "support/sim_worlds.h"

namespace selfcal::bundle {
namespace {

IntrinsicsMask Mask(std::initializer_list<int> set) {
  IntrinsicsMask mask{};
  for (int k : set) mask[k] = true;
  return mask;
}

TEST(BundleIntrinsics, NamesAndGroupsResolveToTheMask) {
  std::vector<int> rho;
  IntrinsicsMask mask{};
  EXPECT_EQ(ResolveParameterNames({"camera", "fy", "cx", "lens"}, 6, &rho, &mask), "");
  EXPECT_EQ(rho.size(), 6u);  // the camera correction only
  EXPECT_EQ(mask, Mask({kMu, kCx, kK1, kK2, kP1, kP2, kK3}));
  mask = {};
  EXPECT_EQ(ResolveParameterNames({"intrinsics"}, 6, &rho, &mask), "");
  EXPECT_TRUE(rho.empty());
  EXPECT_EQ(mask, Mask({kFx, kMu, kCx, kCy, kK1, kK2, kP1, kP2, kK3}));
  const std::string unknown = ResolveParameterNames({"k4"}, 6, &rho, &mask);
  EXPECT_NE(unknown.find("unknown parameter `k4`"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("lens (k1, k2, p1, p2, k3)"), std::string::npos) << unknown;

  BundleOptions options;
  EXPECT_EQ(EstimatedIntrinsicsOf(options, 6), kFocalLengthOnly);  // the default: f_x alone
  options.free_parameters = {"camera", "fx", "k1", "k2", "p1", "p2"};
  EXPECT_EQ(EstimatedIntrinsicsOf(options, 6), Mask({kFx, kK1, kK2, kP1, kP2}));
  options.free_parameters = {"camera"};  // a free list without intrinsics holds them all, f_x too
  EXPECT_EQ(EstimatedIntrinsicsOf(options, 6), IntrinsicsMask{});
  options.free_parameters.clear();
  options.intrinsics = Mask({kFx, kCx, kCy});
  options.held_parameters = {"cy", "k3"};
  EXPECT_EQ(EstimatedIntrinsicsOf(options, 6), Mask({kFx, kCx}));
}

// A camera whose principal point and r^4 term differ from the prior (the truth: c = (325.2, 236.8) px,
// k1 = -0.12, k2 = 0.15; the prior: the image centre, k2 = 0). Freeing cx, cy and k2 (f_x as always)
// recovers them: to 1e-6 without noise, and with 0.2 px noise within 3 of the bundle's own sigmas.
sim::SimResult LensWorld(double noise_px) {
  sim::SimOptions options;
  options.pixel_noise_px = noise_px;
  options.camera.cx_px = 325.2;
  options.camera.cy_px = 236.8;
  options.camera.k1 = -0.12;
  options.camera.k2 = 0.15;
  sim::SimResult world = selfcal::testing::PumaArcWorld(options);
  world.observations.camera.cx_px = 319.5;
  world.observations.camera.cy_px = 239.5;
  world.observations.camera.k2 = 0.0;
  return world;
}

BundleReport SolveLens(const ObservationSet& obs) {
  BundleOptions options;
  options.intrinsics = Mask({kFx, kCx, kCy, kK2});
  return RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, options);
}

TEST(BundleIntrinsics, FreedPrincipalPointAndK2AreRecoveredExactlyWithoutNoise) {
  const sim::SimResult world = LensWorld(0.0);
  const BundleReport r = SolveLens(world.observations);
  ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
  const IntrinsicsVector truth = IntrinsicsOf(world.truth.camera_true);
  EXPECT_EQ(r.intrinsics_estimated, Mask({kFx, kCx, kCy, kK2}));
  for (int k : {kFx, kCx, kCy}) EXPECT_NEAR(r.intrinsics[k], truth[k], 1e-6) << IntrinsicName(k);
  EXPECT_NEAR(r.intrinsics[kK2], truth[kK2], 1e-8);
  EXPECT_EQ(r.intrinsics[kK1], truth[kK1]);  // held: exactly as given
  EXPECT_EQ(r.free_indices, world.truth.perturbed_indices);  // the principal point takes no camera parameter
  for (int i : r.free_indices) EXPECT_NEAR(r.rho[i], world.truth.rho_true[i], 1e-9) << i;
}

TEST(BundleIntrinsics, FreedPrincipalPointAndK2AreWithinThreeSigmaOfTheTruth) {
  const sim::SimResult world = LensWorld(0.2);
  const BundleReport r = SolveLens(world.observations);
  ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
  ASSERT_TRUE(r.covariance_available) << r.covariance_message;
  const int nf = static_cast<int>(r.free_indices.size());
  ASSERT_EQ(r.covariance_free.rows(), nf + 4);
  const IntrinsicsVector truth = IntrinsicsOf(world.truth.camera_true);
  for (int k = 0; k < kNumIntrinsics; ++k) {
    if (!r.intrinsics_estimated[k]) {
      EXPECT_TRUE(std::isnan(r.intrinsics_stddev[k])) << IntrinsicName(k);
      continue;
    }
    const double sd = r.intrinsics_stddev[k];
    ASSERT_TRUE(sd > 0 && std::isfinite(sd)) << IntrinsicName(k);
    const double z = (r.intrinsics[k] - truth[k]) / sd;
    EXPECT_LT(std::abs(z), 3.0) << IntrinsicName(k) << " " << r.intrinsics[k] << " vs " << truth[k] << " +- " << sd;
    std::cout << "[ figure ] " << IntrinsicName(k) << " = " << r.intrinsics[k] << " +- " << sd << " (truth " << truth[k]
              << ", " << z << " sigma)\n";
  }
  // The covariance's last rows are the intrinsics, in Intrinsic order: f_x first.
  EXPECT_DOUBLE_EQ(std::sqrt(r.covariance_free(nf, nf)), r.fx_stddev);
  EXPECT_DOUBLE_EQ(std::sqrt(r.covariance_free(nf + 3, nf + 3)), r.intrinsics_stddev[kK2]);
}

// Views whose dots all lie in one plane through every optical centre that contains the cameras' x axes:
// every point has y = 0 in every camera, so the images say nothing of f_y / f_x. Freeing mu is refused
// before the solve, naming it; the same problem with mu held and k1 freed solves.
TEST(BundleIntrinsics, AnIntrinsicThePosesCannotSeeIsRefusedByName) {
  ObservationSet obs;
  obs.robot = FlangePoseModel(Rigid3());
  obs.flange_from_cam_known = true;
  obs.pixel_noise_px = 0.2;
  obs.camera.k1 = -0.05;
  std::vector<Eigen::Vector3d> dots;
  for (int d = 0; d < 24; ++d) dots.emplace_back(-0.3 + 0.6 * (d % 6) / 5.0, 0.0, 0.8 + 0.1 * (d / 6) + 0.01 * (d % 3));
  for (int i = 0; i < 8; ++i) {
    const double angle = -0.25 + 0.5 * i / 7.0;  // about the base y axis: the cameras' y axes stay base y
    const Rigid3 base_from_cam(ExpSO3<double>(Eigen::Vector3d(0, angle, 0)),
                               Eigen::Vector3d(0.6 * std::sin(angle) * -1.0, 0.0, 0.05 * i));
    PoseObservation pose;
    pose.id = "p" + std::to_string(i);
    pose.base_from_flange = base_from_cam;
    for (size_t d = 0; d < dots.size(); ++d) {
      const auto uv = Project(obs.camera, base_from_cam.Inverse() * dots[d]);
      if (uv && InImage(obs.camera, *uv, 5.0)) pose.dots_px[static_cast<int>(d)] = *uv;
    }
    obs.poses.push_back(pose);
  }
  ASSERT_EQ(obs.Validate(), "");
  BundleOptions options;
  options.free_parameters = {"camera", "mu"};
  const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, options);
  EXPECT_EQ(r.outcome, Outcome::kDegenerate) << r.message;
  EXPECT_NE(r.message.find("mu is not identifiable"), std::string::npos) << r.message;
  options.free_parameters = {"camera", "k1"};
  const BundleReport held = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, options);
  EXPECT_EQ(held.outcome, Outcome::kConverged) << held.message;
  EXPECT_TRUE(held.intrinsics_estimated[kK1] && !held.intrinsics_estimated[kMu]);
}

}  // namespace
}  // namespace selfcal::bundle

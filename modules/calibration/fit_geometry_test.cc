#include "calibration/fit_geometry.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "calibration/calibrate.h"
#include "support/sim_worlds.h"

namespace selfcal::calibration {
namespace {

double Rms(const std::vector<ObservedResidual>& residuals) {
  double sum2 = 0;
  for (const ObservedResidual& r : residuals) sum2 += r.residual_px.squaredNorm();
  return residuals.empty() ? NAN : std::sqrt(sum2 / residuals.size());
}

// Noise-free: every identification residual vanishes, and the camera poses are the truth's, up to the
// gauge (compared relative to the first pose).
TEST(FitGeometry, NoiseFreeCamerasAreTheTruthAndResidualsVanish) {
  const sim::SimResult world = testing::PumaArcWorld(0.0, 1, 1);
  const CalibrationReport report = Calibrate(world.observations, {});
  ASSERT_TRUE(report.accepted()) << report.message;
  const FitGeometry& g = report.bundle->fit_geometry;
  const ObservationSet& obs = world.observations;
  ASSERT_EQ(g.camera_poses.size(), obs.poses.size());
  const Rigid3 ref_from_base = g.camera_poses[0].base_from_cam.Inverse();
  const Rigid3 true_ref_from_base = world.truth.base_from_cam[0].Inverse();
  for (size_t i = 0; i < obs.poses.size(); ++i) {
    EXPECT_EQ(g.camera_poses[i].pose_id, obs.poses[i].id);
    EXPECT_EQ(g.camera_poses[i].role, obs.poses[i].role);
    const PoseDifference d = ComparePoses(ref_from_base * g.camera_poses[i].base_from_cam,
                                          true_ref_from_base * world.truth.base_from_cam[i]);
    EXPECT_LT(d.position_m, 1e-8) << obs.poses[i].id;
    EXPECT_LT(d.rotation_rad, 1e-8) << obs.poses[i].id;
  }
  ASSERT_EQ(static_cast<int>(g.identification_residuals.size()), report.bundle->bundle.num_observations);
  for (const ObservedResidual& r : g.identification_residuals) {
    EXPECT_LT(r.residual_px.norm(), 1e-6) << r.pose_id << " dot " << r.dot_id;
  }
}

// With noise and one gross outlier: the residuals are the final fit's (the screened observation left
// out), so their count and RMS are the bundle's own; the held-out residuals are those of its figure.
TEST(FitGeometry, ResidualsAreTheFinalFitsAndTheHeldOutFigures) {
  sim::SimResult world = testing::PumaArcWorld(0.3, 2, 2);
  ObservationSet& obs = world.observations;
  const int first = obs.PosesWithRole(PoseRole::kIdentification).front();
  auto outlier = obs.poses[first].dots_px.begin();
  outlier->second += Eigen::Vector2d(25.0, -15.0);
  const std::pair<std::string, int> outlier_key{obs.poses[first].id, outlier->first};
  const CalibrationReport report = Calibrate(obs, {});
  ASSERT_TRUE(report.accepted()) << report.message;
  const bundle::BundleReport& b = report.bundle->bundle;
  const FitGeometry& g = report.bundle->fit_geometry;
  std::set<std::pair<std::string, int>> removed;
  for (const bundle::RemovedObservation& o : b.removed) removed.insert({o.pose_id, o.dot_id});
  ASSERT_EQ(removed.count(outlier_key), 1u) << "the screen kept the 29 px outlier";
  ASSERT_EQ(static_cast<int>(g.identification_residuals.size()), b.num_observations);
  EXPECT_NEAR(Rms(g.identification_residuals), b.rms_reprojection_px, 1e-9 * b.rms_reprojection_px);
  for (const ObservedResidual& r : g.identification_residuals) {
    EXPECT_EQ(removed.count({r.pose_id, r.dot_id}), 0u) << r.pose_id << " dot " << r.dot_id;
    const PoseObservation& pose = *std::find_if(obs.poses.begin(), obs.poses.end(),
                                                [&](const PoseObservation& p) { return p.id == r.pose_id; });
    EXPECT_EQ(pose.role, PoseRole::kIdentification);
    EXPECT_EQ(r.pixel_px, pose.dots_px.at(r.dot_id));
  }
  const HeldOutReprojection& h = report.bundle->heldout;
  ASSERT_TRUE(h.ok) << h.message;
  ASSERT_EQ(static_cast<int>(h.residuals.size()), h.overall.num_residuals);
  // Its RMS is per coordinate, the bundle's of the 2-D error.
  EXPECT_NEAR(Rms(h.residuals) / std::sqrt(2.0), h.overall.rms_px, 1e-9 * h.overall.rms_px);
}

// No geometry from a bundle that did not solve: not run, or stopped as degenerate with its start's rho.
TEST(FitGeometry, EmptyWithoutASolve) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  bundle::BundleReport not_run;  // kNotRun: no rho
  EXPECT_TRUE(FitGeometryOf(world.observations, not_run).camera_poses.empty());
  world.observations.poses.resize(3);  // too few poses to identify the generic set
  const CalibrationReport report = Calibrate(world.observations, {});
  ASSERT_EQ(report.bundle->bundle.outcome, bundle::Outcome::kDegenerate) << report.bundle->bundle.message;
  ASSERT_EQ(report.bundle->bundle.rho.size(), world.observations.robot.num_parameters());
  EXPECT_TRUE(report.bundle->fit_geometry.camera_poses.empty());
  EXPECT_TRUE(report.bundle->fit_geometry.identification_residuals.empty());
}

}  // namespace
}  // namespace selfcal::calibration

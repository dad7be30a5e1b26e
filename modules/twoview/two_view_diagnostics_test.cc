// Two-view estimator: the diagnostics on the final residuals (G10) and the choice among OpenCV's stacked
// essential matrices (G2).
#include <iostream>
#include <limits>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "twoview/two_view.h"
#include "twoview/two_view_internal.h"
#include "twoview/two_view_test_util.h"

namespace selfcal::twoview {
namespace {

using namespace test_scene;  // NOLINT(build/namespaces): the shared scene vocabulary of these tests

// ---- G10: diagnostics -------------------------------------------------------------------------------

// Points filling the 640 x 480 image (r up to 400 px), where a lens distortion shows most.
SceneSpec WideSpec() {
  SceneSpec spec;
  spec.box_half = Eigen::Vector3d(0.25, 0.19, 0.1);
  return spec;
}

bool HasWarning(const TwoViewReport& report, const std::string& prefix) {
  for (const std::string& w : report.warnings) {
    if (w.rfind(prefix, 0) == 0) return true;
  }
  return false;
}
const char kRadialWarning[] = "intrinsics/distortion suspect: residuals grow with radius (";
const char kInlierWarning[] = "inlier ratio ";

// Clean data, fresh scene and noise per trial, two layouts: the requirement is no warning of any kind
// in at least 99 % of trials (two_view.cc quotes the rate over 1000 trials per layout).
TEST(TwoViewDiagnostics, G10CleanDataRaisesNoWarning) {
  constexpr int kTrials = 250;
  for (bool wide : {false, true}) {
    std::mt19937_64 rng(wide ? 41 : 40);
    int warned = 0;
    for (int trial = 0; trial < kTrials; ++trial) {
      Scene scene = MakeScene(wide ? WideSpec() : SceneSpec{}, &rng);
      AddNoise(0.5, &rng, &scene.pixels1);
      AddNoise(0.5, &rng, &scene.pixels2);
      const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
      ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
      if (!report.warnings.empty()) {
        ++warned;
        std::cout << "[ figures  ] false alarm: " << report.warnings.front() << "\n";
      }
    }
    std::cout << "[ figures  ] G10 clean, 0.5 px, " << (wide ? "points filling the image" : "test scene") << ": "
              << warned << " of " << kTrials << " trials warned\n";
    EXPECT_LE(warned, kTrials / 100);
  }
  // Exact data: residuals are rounding errors and must not look like a trend.
  std::mt19937_64 rng(42);
  for (bool wide : {false, true}) {
    const Scene scene = MakeScene(wide ? WideSpec() : SceneSpec{}, &rng);
    const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
    ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
    EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  }
}

// Pixels of a lens with k1 = -0.15 (9.6 px of barrel distortion in the image corners) handed over as if
// undistorted. f_x and the pose absorb most of it (the focal came out 4-60 % too long in trials), the residual
// RMS barely changes, yet the signed residuals keep a radial signature.
TEST(TwoViewDiagnostics, G10UncorrectedRadialDistortionIsFlagged) {
  constexpr int kTrials = 60;
  std::mt19937_64 rng(43);
  const CameraIntrinsics assumed = TestCamera();  // k1 = 0
  for (double sigma : {0.0, 0.5}) {
    int flagged = 0;
    for (int trial = 0; trial < (sigma == 0 ? 3 : kTrials); ++trial) {
      SceneSpec spec = WideSpec();
      spec.camera.k1 = -0.15;
      Scene scene = MakeScene(spec, &rng);
      AddNoise(sigma, &rng, &scene.pixels1);
      AddNoise(sigma, &rng, &scene.pixels2);
      const TwoViewReport report = EstimateTwoView(Options(), assumed, scene.pixels1, scene.pixels2);
      ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
      if (HasWarning(report, kRadialWarning)) {
        ++flagged;
        // The estimated k1 has the right sign.
        EXPECT_NE(report.warnings.front().find("k1 = -0."), std::string::npos) << report.warnings.front();
      }
      if (trial == 0 && !report.warnings.empty()) std::cout << "[ figures  ] " << report.warnings.front() << "\n";
    }
    const int trials = sigma == 0 ? 3 : kTrials;
    std::cout << "[ figures  ] G10 k1 = -0.15 uncorrected, sigma " << sigma << ": " << flagged << " of " << trials
              << " flagged\n";
    // The study (DISABLED_G10RadialWarningStudy) measured 299 of 300 at 0.5 px; 95 % leaves room.
    EXPECT_GE(flagged, sigma == 0 ? trials : (95 * trials) / 100);
  }
}

// The study behind the figures quoted in two_view.cc (about 15 s; run with
// --gtest_also_run_disabled_tests): radial warnings per 1000 trials at 0.5 px for both layouts, clean,
// with 10 % and 40 % random mismatches, and with k1 = -0.15 left uncorrected.
TEST(TwoViewDiagnostics, DISABLED_G10RadialWarningStudy) {
  struct Case {
    double k1, outlier_fraction;
    int trials;
  };
  for (const Case& c : {Case{0, 0, 1000}, Case{0, 0.1, 1000}, Case{0, 0.4, 1000}, Case{-0.15, 0, 300}}) {
    for (bool wide : {false, true}) {
      std::mt19937_64 rng(wide ? 51 : 50);
      std::uniform_real_distribution<double> u(0, 639), v(0, 479);
      int runs = 0, flagged = 0;
      for (int trial = 0; trial < c.trials; ++trial) {
        SceneSpec spec = wide ? WideSpec() : SceneSpec{};
        spec.camera.k1 = c.k1;
        Scene scene = MakeScene(spec, &rng);
        AddNoise(0.5, &rng, &scene.pixels1);
        AddNoise(0.5, &rng, &scene.pixels2);
        const int num_outliers = static_cast<int>(c.outlier_fraction * scene.points.size());
        for (int i = 0; i < num_outliers; ++i) scene.pixels2[i] = Eigen::Vector2d(u(rng), v(rng));
        const TwoViewReport report = EstimateTwoView(Options(), TestCamera(), scene.pixels1, scene.pixels2);
        if (report.outcome != Outcome::kSuccess) continue;
        ++runs;
        flagged += HasWarning(report, kRadialWarning);
      }
      std::cout << "[ figures  ] k1 " << c.k1 << ", " << 100 * c.outlier_fraction << " % mismatches, "
                << (wide ? "points filling the image" : "test scene") << ": " << flagged << " of " << runs
                << " successful trials warned (" << c.trials - runs << " not successful)\n";
    }
  }
}

TEST(TwoViewDiagnostics, G10LowInlierRatioIsFlagged) {
  std::mt19937_64 rng(44);
  std::uniform_real_distribution<double> u(0, 639), v(0, 479);
  Scene scene = MakeScene(SceneSpec{}, &rng);
  AddNoise(0.2, &rng, &scene.pixels1);
  AddNoise(0.2, &rng, &scene.pixels2);
  const TwoViewReport clean = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(clean.outcome, Outcome::kSuccess) << clean.message;
  EXPECT_FALSE(HasWarning(clean, kInlierWarning));
  for (int i = 0; i < 24; ++i) scene.pixels2[i] = Eigen::Vector2d(u(rng), v(rng));  // 30 % mismatches
  const TwoViewReport report = EstimateTwoView(Options(), scene.camera, scene.pixels1, scene.pixels2);
  ASSERT_EQ(report.outcome, Outcome::kSuccess) << report.message;
  ASSERT_TRUE(HasWarning(report, kInlierWarning));
  const double ratio = static_cast<double>(report.num_inliers) / 80;
  EXPECT_LT(ratio, 0.8);
  std::ostringstream expected;
  expected << "inlier ratio " << ratio << ": outliers or wrong intrinsics";
  EXPECT_EQ(report.warnings.front().rfind(expected.str(), 0), 0u) << report.warnings.front();
}

// ---- G2: stacked essential matrices -----------------------------------------------------------------

Eigen::Vector2d ProjectAnyDepth(const CameraIntrinsics& camera, const Eigen::Vector3d& p) {
  // Also for a point behind the camera, which images through the centre like any other.
  return Eigen::Vector2d(camera.fx_px * p.x() / p.z() + camera.cx_px,
                         camera.fx_px * camera.mu * p.y() / p.z() + camera.cy_px);
}

Eigen::Matrix3d EssentialOf(const Rigid3& cam2_from_cam1) {
  return Skew<double>(cam2_from_cam1.translation) * cam2_from_cam1.rotation;
}

// Three stacked candidates, as OpenCV's 5-point solver returns them. 40 correspondences come from the
// true pose (points in front), 50 from another pose B whose points lie in front of camera 1 but half of
// them behind camera 2: E_B has the most inliers (50 > 40), but no decomposition of it puts more than
// about half of them in front of both cameras. Candidate 0 is the truth with R off by 5 deg.
TEST(TwoViewOpenCv, G2StackedCandidatesChooseByInliersAndCheirality) {
  std::mt19937_64 rng(45);
  SceneSpec spec;
  spec.num_points = 40;
  const Scene scene = MakeScene(spec, &rng);
  std::vector<Eigen::Vector2d> pixels1 = scene.pixels1, pixels2 = scene.pixels2;
  const Rigid3 pose_b(RotY(0.1), Eigen::Vector3d(0.1, 0.02, -0.75));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int behind_cam2 = 0;
  for (int k = 0; k < 50; ++k) {
    const double depth = (k % 2 == 0 ? 0.525 : 0.975) + 0.075 * unit(rng);
    const Eigen::Vector3d p(0.15 * unit(rng), 0.12 * unit(rng), depth);
    const Eigen::Vector3d p2 = pose_b * p;
    if (p2.z() < 0) ++behind_cam2;
    pixels1.push_back(ProjectAnyDepth(scene.camera, p));
    pixels2.push_back(ProjectAnyDepth(scene.camera, p2));
  }
  ASSERT_EQ(behind_cam2, 25);

  Eigen::MatrixXd stacked(9, 3);
  stacked.middleRows<3>(0) =
      EssentialOf(Rigid3(ExpSO3<double>(Eigen::Vector3d(0, 0, DegToRad(5))) * scene.cam2_from_cam1.rotation,
                         scene.cam2_from_cam1.translation));
  stacked.middleRows<3>(3) = EssentialOf(pose_b);
  stacked.middleRows<3>(6) = -3.0 * EssentialOf(scene.cam2_from_cam1);  // scale and sign are free
  const internal::EssentialChoice choice =
      internal::ChooseEssentialCandidate(stacked, scene.camera, pixels1, pixels2, {}, 1.0);
  ASSERT_EQ(choice.index, 2) << choice.message;
  EXPECT_EQ(choice.num_candidates, 3);
  EXPECT_GT(choice.num_inliers[1], choice.num_inliers[2]);  // inliers alone would pick E_B
  EXPECT_GE(choice.num_inliers[1], 50);
  EXPECT_LE(choice.num_good[1], 30);
  EXPECT_LT(choice.num_inliers[0], 10);
  EXPECT_GE(choice.num_good[2], 40);
  for (int i = 0; i < 40; ++i) EXPECT_TRUE(choice.good[i]) << i;
  EXPECT_LT(RotationError(scene.cam2_from_cam1.rotation, choice.rotation), 1e-9);
  EXPECT_LT(DirectionError(scene.cam2_from_cam1.translation, choice.translation), 1e-9);
  std::cout << "[ figures  ] G2 candidates: inliers " << choice.num_inliers[0] << "/" << choice.num_inliers[1] << "/"
            << choice.num_inliers[2] << ", in front " << choice.num_good[0] << "/" << choice.num_good[1] << "/"
            << choice.num_good[2] << "; " << choice.message << "\n";

  // A RANSAC mask restricts the points each candidate may count.
  std::vector<bool> only_b(pixels1.size(), false);
  for (size_t i = 40; i < only_b.size(); ++i) only_b[i] = true;
  EXPECT_EQ(internal::ChooseEssentialCandidate(stacked, scene.camera, pixels1, pixels2, only_b, 1.0).index, 1);
}

TEST(TwoViewOpenCv, G2MalformedOrNonFiniteCandidatesAreNeverPassedOn) {
  std::mt19937_64 rng(46);
  const Scene scene = MakeScene(SceneSpec{}, &rng);
  const Eigen::Matrix3d e = EssentialOf(scene.cam2_from_cam1);
  for (const Eigen::MatrixXd& bad : {Eigen::MatrixXd(0, 3), Eigen::MatrixXd(Eigen::MatrixXd::Ones(4, 3)),
                                     Eigen::MatrixXd(Eigen::MatrixXd::Ones(3, 4))}) {
    const internal::EssentialChoice choice =
        internal::ChooseEssentialCandidate(bad, scene.camera, scene.pixels1, scene.pixels2, {}, 1.0);
    EXPECT_EQ(choice.index, -1);
    EXPECT_EQ(choice.num_candidates, 0);
    EXPECT_NE(choice.message.find("is not 3N x 3"), std::string::npos) << choice.message;
  }
  Eigen::MatrixXd stacked(9, 3);
  stacked.middleRows<3>(0).setConstant(std::numeric_limits<double>::quiet_NaN());
  stacked.middleRows<3>(3).setZero();
  stacked.middleRows<3>(6) = e;
  const internal::EssentialChoice choice =
      internal::ChooseEssentialCandidate(stacked, scene.camera, scene.pixels1, scene.pixels2, {}, 1.0);
  ASSERT_EQ(choice.index, 2) << choice.message;
  EXPECT_EQ(choice.num_good[2], 80);
  EXPECT_NE(choice.message.find("(2 non-finite or rejected by recoverPose)"), std::string::npos) << choice.message;
  // Nothing usable at all.
  stacked.middleRows<3>(6).setZero();
  EXPECT_EQ(internal::ChooseEssentialCandidate(stacked, scene.camera, scene.pixels1, scene.pixels2, {}, 1.0).index, -1);
}

}  // namespace
}  // namespace selfcal::twoview

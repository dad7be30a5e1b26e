// BundleSampleCameras (bundled_cameras.h) and NameSeenOnce (seen_once.h) on cameras around a box of dots,
// started up to 0.5 deg and 2 mm off with an f_x 1 % off: the bundle brings the samples' relative
// rotations and f_x to the truth; a dot held by one sample is then named in the
// others under its true id; with too few further samples, or two unnamed detections in its gates, it is
// not named at all.
#include "acquisition/seen_once.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "acquisition/bundled_cameras.h"
#include "acquisition/prediction_test_cell.h"

namespace selfcal::acquisition {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Ten cameras on an arc around a box of 80 dots 0.6 m away, each looking at the box's centre: the true
// cameras. The samples' cameras as a nominal model would put them are those moved by up to 0.3 deg and
// 2 mm, given as ViewedSample::base_from_cam; the believed f_x is 1 % off the truth.
struct Scene {
  PredictionModel truth_model, believed;
  std::vector<Rigid3> true_cams;
  std::vector<std::map<int, Eigen::Vector2d>> truth;  // per sample: every dot in view, true (noisy) pixel
  std::vector<ViewedSample> samples;
  std::vector<tracking::DetectionReport> detected;  // every dot in view, in id order
  std::vector<int> seen_once;                       // the dots only sample 0 holds
};

Rigid3 Looking(const Eigen::Vector3d& eye, const Eigen::Vector3d& at) {
  const Eigen::Vector3d z = (at - eye).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  Eigen::Matrix3d r;
  r << x, z.cross(x), z;
  return Rigid3(r, eye);  // base_from_cam
}

Scene MakeScene(int num_samples) {
  Scene s;
  s.truth_model.robot = testing::Puma560();
  s.truth_model.pixel_noise_px = 0.2;
  s.believed = s.truth_model;
  s.believed.camera.fx_px *= 1.01;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> box(-0.12, 0.12), err(-1, 1);
  std::normal_distribution<double> noise(0, s.truth_model.pixel_noise_px);
  std::vector<Eigen::Vector3d> dots;
  for (int i = 0; i < 80; ++i) dots.emplace_back(box(rng), box(rng), 0.6 + box(rng));
  for (int k = 0; k < num_samples; ++k) {
    const double a = 0.45 * (k / std::max(1.0, num_samples - 1.0) - 0.5);  // about +-13 deg
    const Eigen::Vector3d eye(0.6 * std::sin(a), 0.05 * std::cos(3.0 * k), 0.6 - 0.6 * std::cos(a));
    s.true_cams.push_back(Looking(eye, Eigen::Vector3d(0, 0, 0.6)));
    const Rigid3 cam_from_base = s.true_cams.back().Inverse();
    ViewedSample sample;
    sample.joints_rad = Eigen::VectorXd::Zero(6);
    const Eigen::Vector3d tilt(err(rng), err(rng), err(rng));
    sample.base_from_cam = s.true_cams.back() * Rigid3(Eigen::AngleAxisd(0.005 * tilt.norm(), tilt.normalized()).toRotationMatrix(),
                                                       0.002 * Eigen::Vector3d(err(rng), err(rng), err(rng)));
    if (k == 0) sample.base_from_cam = s.true_cams.back();  // the gauge
    s.truth.emplace_back();
    tracking::DetectionReport report;
    for (size_t i = 0; i < dots.size(); ++i) {
      const std::optional<Eigen::Vector2d> uv = Project(s.truth_model.camera, cam_from_base * dots[i]);
      if (!uv || !InImage(s.truth_model.camera, *uv, 5)) continue;
      const int id = static_cast<int>(i);
      const Eigen::Vector2d px = *uv + Eigen::Vector2d(noise(rng), noise(rng));
      s.truth.back()[id] = px;
      if (k == 0 || id % 12 != 5) sample.dots_px[id] = px;  // every twelfth dot: lost after sample 0
      tracking::DotDetection d;
      d.centroid_px = px;
      d.area_px2 = 80;
      report.dots.push_back(d);
    }
    s.samples.push_back(sample);
    s.detected.push_back(report);
  }
  for (const auto& [id, px] : s.truth[0]) {
    if (id % 12 == 5) s.seen_once.push_back(id);
  }
  return s;
}

// The rotation of sample k's camera relative to sample 0's, from a list of base_from_cam.
Eigen::Matrix3d Relative(const std::vector<Rigid3>& base_from_cams, size_t k) {
  return base_from_cams[0].rotation.transpose() * base_from_cams[k].rotation;
}

TEST(BundledCameras, TheSamplesRelativeRotationsAndTheFocalLengthComeToTheSolutionTheTruthGives) {
  const Scene s = MakeScene(10);
  const BundledCameras b = BundleSampleCameras(s.believed, s.samples, DotPredictionOptions());
  ASSERT_TRUE(b.ok) << b.message;
  // The same bundle started at the truth: where the noise leaves the solution.
  std::vector<ViewedSample> at_truth = s.samples;
  for (size_t k = 0; k < at_truth.size(); ++k) at_truth[k].base_from_cam = s.true_cams[k];
  const BundledCameras best = BundleSampleCameras(s.truth_model, at_truth, DotPredictionOptions());
  ASSERT_TRUE(best.ok) << best.message;
  EXPECT_NEAR(b.fx_px, best.fx_px, 0.05);  // the solver's tolerance; the noise leaves it 2.5 px off
  const double fx_true = s.truth_model.camera.fx_px;
  EXPECT_LT(std::abs(b.fx_px - fx_true), 0.5 * std::abs(s.believed.camera.fx_px - fx_true)) << b.fx_px;
  std::vector<Rigid3> given;
  for (const ViewedSample& v : s.samples) given.push_back(*v.base_from_cam);
  double sum_bundled = 0, sum_given = 0;
  for (size_t k = 1; k < s.samples.size(); ++k) {
    const Eigen::Matrix3d truth = Relative(s.true_cams, k);
    const double bundled = Eigen::AngleAxisd(truth.transpose() * Relative(b.base_from_cams, k)).angle();
    EXPECT_LT(Eigen::AngleAxisd(Relative(best.base_from_cams, k).transpose() * Relative(b.base_from_cams, k)).angle(),
              1e-5) << "sample " << k;
    sum_bundled += bundled;
    sum_given += Eigen::AngleAxisd(truth.transpose() * Relative(given, k)).angle();
  }
  EXPECT_LT(sum_bundled, 0.5 * sum_given) << "mean error " << sum_bundled / 9 << " rad, given " << sum_given / 9;
  EXPECT_LT(b.rms_reprojection_px, 1.5 * s.truth_model.pixel_noise_px);
}

TEST(SeenOnce, ADotOneSampleHoldsIsNamedInTheOthersUnderItsTrueId) {
  Scene s = MakeScene(10);
  PredictionModel model = s.believed;
  UseBundledCameras(BundleSampleCameras(model, s.samples, DotPredictionOptions()), &model, &s.samples);
  const SeenOnceReport r = NameSeenOnce(model, s.samples, s.detected, SeenOnceOptions());
  ASSERT_GE(s.seen_once.size(), 3u);
  EXPECT_GE(r.looked_for, static_cast<int>(s.seen_once.size()));
  int possible = 0;
  for (size_t k = 1; k < s.truth.size(); ++k) {
    for (const int id : s.seen_once) possible += s.truth[k].count(id) ? 1 : 0;
  }
  for (const SeenOnceName& n : r.named) {
    ASSERT_TRUE(s.truth[static_cast<size_t>(n.sample)].count(n.dot.id)) << "dot " << n.dot.id;
    EXPECT_LT((n.dot.centroid_px - s.truth[static_cast<size_t>(n.sample)].at(n.dot.id)).norm(), 1e-9)
        << "dot " << n.dot.id << " named on another's blob in sample " << n.sample;
  }
  // Measured: 53 of 63. One dot of the seven lies, in several samples, within its short gate of a named
  // neighbour (the box's dots are placed at random, closer than a real scene's spacing rule allows),
  // which counts against it: it stays unnamed, as it should.
  EXPECT_GE(static_cast<int>(r.named.size()), possible * 3 / 4) << r.rivalled << " rivalled, " << r.conflicts
                                                                  << " in conflict";
}

TEST(SeenOnce, WithTooFewFurtherSamplesToSupportItADotIsNotNamed) {
  Scene s = MakeScene(4);  // the dot's sample, the hypothesis's, two further: three supports are needed
  PredictionModel model = s.believed;
  UseBundledCameras(BundleSampleCameras(model, s.samples, DotPredictionOptions()), &model, &s.samples);
  EXPECT_TRUE(NameSeenOnce(model, s.samples, s.detected, SeenOnceOptions()).named.empty());
  SeenOnceOptions two;
  two.min_support = 2;
  EXPECT_FALSE(NameSeenOnce(model, s.samples, s.detected, two).named.empty())
      << "with two supports enough, the dots are found: the rule is what kept them out";
}

TEST(SeenOnce, TwoUnnamedDetectionsInItsGatesNameNeither) {
  Scene s = MakeScene(10);
  const int target = s.seen_once.front();
  for (size_t k = 1; k < s.samples.size(); ++k) {
    if (!s.truth[k].count(target)) continue;
    tracking::DotDetection twin;
    twin.centroid_px = s.truth[k].at(target) + Eigen::Vector2d(0.5, -0.4);  // inside every short gate
    twin.area_px2 = 80;
    s.detected[k].dots.push_back(twin);
  }
  PredictionModel model = s.believed;
  UseBundledCameras(BundleSampleCameras(model, s.samples, DotPredictionOptions()), &model, &s.samples);
  const SeenOnceReport r = NameSeenOnce(model, s.samples, s.detected, SeenOnceOptions());
  for (const SeenOnceName& n : r.named) EXPECT_NE(n.dot.id, target) << "sample " << n.sample;
  EXPECT_GE(r.dots_named, 1) << "the other dots seen once are still named";
}

}  // namespace
}  // namespace selfcal::acquisition

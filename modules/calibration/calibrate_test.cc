#include "calibration/calibrate.h"

#include <gtest/gtest.h>

#include "support/sim_worlds.h"

namespace selfcal::calibration {
namespace {

// The facade runs what the method names and returns exactly what the stages return: the same bundle
// result as calling the stages by hand, the model of the chosen method, and the verdict of that method.
TEST(Calibrate, BundleMethodReturnsTheBundleStagesModel) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  const ObservationSet& obs = world.observations;
  const CalibrationReport report = Calibrate(obs, CalibrateOptions());
  ASSERT_TRUE(report.accepted()) << report.message;
  ASSERT_TRUE(report.bundle.has_value());
  ASSERT_TRUE(report.model.has_value());
  const PaperPipelineReport paper = RunPaperPipeline(obs, PaperPipelineOptions());
  const BundleStageReport stage = RunBundleStage(obs, paper, BundleStageOptions());
  EXPECT_EQ(report.model->parameters, stage.bundle.rho);
  EXPECT_EQ(report.model->camera.fx_px, stage.bundle.fx_px);
  EXPECT_EQ(report.model->method_description, "kinematic bundle adjustment");
  // The chosen method's held-out figures are the bundle's, and they beat the nominal model.
  EXPECT_EQ(report.verification_calibrated().rms_error_m, stage.verification.rms_error_m);
  EXPECT_LT(report.verification_calibrated().rms_error_m, report.verification_nominal().rms_error_m);
  // Against the hidden truth, within the noise: f_x within 5 sigma of the bundle's own std.
  EXPECT_NEAR(report.model->camera.fx_px, world.truth.camera_true.fx_px, 5 * stage.bundle.fx_stddev);
}

TEST(Calibrate, PaperMethodRunsNoBundleAndWritesThePapersModel) {
  const sim::SimResult world = testing::PumaArcWorld(0.0, 1, 1);
  CalibrateOptions options;
  options.method = Method::kPaper;
  const CalibrationReport report = Calibrate(world.observations, options);
  EXPECT_FALSE(report.bundle.has_value());
  ASSERT_TRUE(report.accepted()) << report.message;
  ASSERT_TRUE(report.model.has_value());
  EXPECT_EQ(report.model->camera.fx_px, report.paper.fx_px);
  EXPECT_EQ(report.model->parameters.size(), 0);
  EXPECT_EQ(report.model->method_description, "paper pipeline");
}

// Too few poses: the verdict says degenerate, and no model is offered for writing (K4).
TEST(Calibrate, NoModelWithoutAnAcceptedVerdict) {
  sim::SimResult world = testing::PumaArcWorld(0.2, 1, 1);
  ObservationSet obs = world.observations;
  obs.poses.resize(3);
  const CalibrationReport report = Calibrate(obs, CalibrateOptions());
  EXPECT_FALSE(report.accepted());
  EXPECT_NE(report.verdict, Verdict::kAccepted);
  EXPECT_FALSE(report.model.has_value());
  EXPECT_FALSE(report.message.empty());
}

TEST(Calibrate, MethodNamesRoundTrip) {
  for (Method m : {Method::kBundle, Method::kPaper}) EXPECT_EQ(ParseMethod(MethodName(m)), m);
  EXPECT_FALSE(ParseMethod("lm").has_value());
  EXPECT_STREQ(VerdictName(VerdictFor(bundle::Outcome::kNoConvergence)), "unconverged");
  EXPECT_EQ(VerdictFor(Outcome::kScaleUnresolved), Verdict::kScaleUnresolved);
}

}  // namespace
}  // namespace selfcal::calibration

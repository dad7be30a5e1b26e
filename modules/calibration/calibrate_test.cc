#include "calibration/calibrate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

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

// A wrong model the calibration may not correct: f_x held 2 % off the truth. The solve converges, and the
// verdict refuses the model, saying why. The
// same sets with f_x free are accepted (the held-out test passes at 95 %: 3 of 3 with probability 0.86,
// so the bound asks for 2).
TEST(Calibrate, AWrongFocalLengthHeldFixedIsRejected) {
  int correct_accepted = 0;
  for (uint64_t seed = 21; seed < 24; ++seed) {
    const sim::SimResult world = testing::PumaArcWorld(0.3, seed, seed);
    ObservationSet obs = world.observations;
    correct_accepted += Calibrate(obs, CalibrateOptions()).accepted() ? 1 : 0;
    obs.camera.fx_px = 1.02 * world.truth.camera_true.fx_px;
    CalibrateOptions options;
    options.bundle.bundle.held_parameters = {"fx"};
    const CalibrationReport report = Calibrate(obs, options);
    ASSERT_TRUE(report.bundle.has_value());
    EXPECT_EQ(report.bundle->bundle.fx_px, obs.camera.fx_px) << "a held f_x is the stated one";
    EXPECT_EQ(report.verdict, Verdict::kRejected) << seed << ": " << report.message;
    EXPECT_FALSE(report.model.has_value());
    ASSERT_FALSE(report.acceptance.Reasons().empty());
    // Refused by the score test of the held f_x, and by the held-out test where the weak joint parameters,
    // held with their manufacturing tolerance in the test's covariance, cannot take the error up (measured:
    // seed 21 by both, 22 and 23 by the score test alone).
    bool named = false;
    for (const std::string& reason : report.acceptance.Reasons()) {
      named = named || reason.find("the images disagree with a held value, most with fx") != std::string::npos;
    }
    EXPECT_TRUE(named) << report.acceptance.Reasons()[0];
  }
  EXPECT_GE(correct_accepted, 2);
}

// A half-turn in a joint's angle is a wrong description absorbed into an equivalent parameterisation
// (a negated joint reading fits exactly with j4.alpha and j5.theta turned by multiples of 180 deg): refused,
// naming the parameter. Corrections within 45 deg and 100 mm pass.
TEST(Calibrate, AHalfTurnCorrectionIsImplausible) {
  const sim::SimResult world = testing::PumaArcWorld(0.0, 1, 1);
  const RobotModel& robot = world.observations.robot;
  const KinematicParameters params(robot.num_joints());
  AcceptanceInputs in;
  in.robot = &robot;
  in.corrections = Eigen::VectorXd::Zero(robot.num_parameters());
  in.corrections[params.IndexOf("j4.alpha")] = 0.7;   // 40 deg
  in.corrections[params.IndexOf("j2.a")] = 0.09;      // 90 mm
  const auto plausible = [](const Acceptance& a) {
    return *std::find_if(a.checks.begin(), a.checks.end(),
                         [](const AcceptanceCheck& c) { return c.name == "plausible_corrections"; });
  };
  EXPECT_EQ(plausible(AcceptanceOf(in)).status, CheckStatus::kPassed);
  EXPECT_TRUE(AcceptanceOf(in).Passed());
  in.corrections[params.IndexOf("j5.theta")] = 3 * M_PI;
  const Acceptance refused = AcceptanceOf(in);
  EXPECT_EQ(plausible(refused).name, "plausible_corrections");
  EXPECT_EQ(plausible(refused).status, CheckStatus::kFailed);
  EXPECT_FALSE(refused.Passed());
  EXPECT_EQ(refused.Reasons().size(), 1u);
  EXPECT_NE(refused.Reasons()[0].find("j5.theta is corrected by 540.0 deg"), std::string::npos) << refused.Reasons()[0];
  in.corrections[params.IndexOf("j5.theta")] = 0;
  in.corrections[params.IndexOf("j3.d")] = -12.0;  // metres: lengths traded against angles on parallel axes
  const Acceptance lengths = AcceptanceOf(in);
  ASSERT_EQ(lengths.Reasons().size(), 1u);
  EXPECT_NE(lengths.Reasons()[0].find("j3.d is corrected by 1.2e+04 mm"), std::string::npos) << lengths.Reasons()[0];
}

// Issue 36: with check distances none of which could be measured (their dots not triangulated), calibrate
// said "the 40 check distances are measured at 0 mm RMS error": the 0 of an empty mean. Now no figure is
// given as measured unless it was, and a partly measured set says how many.
TEST(Calibrate, CheckDistancesNoneCouldMeasureGiveNoFigure) {
  VerificationSummary none, some, all;
  none.checks.resize(40);
  some.checks.resize(40);
  some.num_ok = 30;
  some.rms_error_m = 0.002;
  all.checks.resize(40);
  all.num_ok = 40;
  all.rms_error_m = 0.004;
  const auto distances = [](const VerificationSummary& cal, const VerificationSummary& nom) {
    AcceptanceInputs in;
    in.distances_calibrated = &cal;
    in.distances_nominal = &nom;
    return AcceptanceOf(in).checks[3];  // heldout_test, cross_validation_test, beats_nominal_heldout, then it
  };
  const AcceptanceCheck unmeasured = distances(none, all);
  EXPECT_EQ(unmeasured.name, "beats_nominal_distances");
  EXPECT_EQ(unmeasured.status, CheckStatus::kNotAvailable);
  EXPECT_EQ(unmeasured.sentence.find("measured at"), std::string::npos) << unmeasured.sentence;
  EXPECT_NE(unmeasured.sentence.find("none of the 40 check distances could be measured with the calibrated model"),
            std::string::npos) << unmeasured.sentence;
  EXPECT_EQ(distances(all, none).status, CheckStatus::kNotAvailable);
  const AcceptanceCheck partly = distances(some, all);
  EXPECT_EQ(partly.status, CheckStatus::kPassed);
  EXPECT_NE(partly.sentence.find("30 of the 40 check distances could be measured with the calibrated model, 40 with the "
                                 "nominal model: the 30 check distances are measured at 2 mm RMS error, 4 mm"),
            std::string::npos) << partly.sentence;
  EXPECT_NE(distances(all, all).sentence.find("the 40 check distances are measured at 4 mm"), std::string::npos);
}

// Issue 36: a verification pose none of whose dots could be predicted was dropped without a word, and the
// calibration accepted on the others. It is an error naming the pose now, and no model is offered.
TEST(Calibrate, AVerificationPoseThatCannotBeUsedIsAnErrorNamingIt) {
  const sim::SimResult world = testing::PumaArcWorld(0.2, 3, 3);
  ObservationSet obs = world.observations;
  const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
  ASSERT_GE(verification.size(), 2u);
  PoseObservation& pose = obs.poses[verification[1]];
  std::map<int, Eigen::Vector2d> unplaced;  // dots no identification image sees
  for (const auto& [id, uv] : pose.dots_px) unplaced[id + 100000] = uv;
  pose.dots_px = unplaced;
  for (const Method method : {Method::kBundle, Method::kPaper}) {
    CalibrateOptions options;
    options.method = method;
    const CalibrationReport report = Calibrate(obs, options);
    EXPECT_EQ(report.verdict, Verdict::kInvalidInput) << MethodName(method) << ": " << report.message;
    EXPECT_FALSE(report.model.has_value());
    EXPECT_EQ(report.message.rfind("verification pose " + pose.id + " cannot be used: none of its dots is predicted", 0),
              0u) << report.message;
  }
}

TEST(Calibrate, MethodNamesRoundTrip) {
  for (Method m : {Method::kBundle, Method::kPaper}) EXPECT_EQ(ParseMethod(MethodName(m)), m);
  EXPECT_FALSE(ParseMethod("lm").has_value());
  EXPECT_STREQ(VerdictName(VerdictFor(bundle::Outcome::kNoConvergence)), "unconverged");
  EXPECT_EQ(VerdictFor(Outcome::kScaleUnresolved), Verdict::kScaleUnresolved);
  EXPECT_STREQ(VerdictName(Verdict::kRejected), "rejected");
}

}  // namespace
}  // namespace selfcal::calibration

namespace selfcal::calibration {
namespace {

// Issue 35: "better than the nominal model" only against a nominal someone gave. A held-out figure whose
// nominal is the solver's own start (a flange-pose set that names no hand-eye transform) is no comparison:
// not available, whatever the two figures are, and so never the reason for a refusal.
TEST(Calibrate, NoComparisonWithANominalModelNobodyGave) {
  HeldOutReprojection calibrated, nominal;
  calibrated.ok = nominal.ok = true;
  calibrated.overall.rms_px = 1.67;
  nominal.overall.rms_px = 1.61;
  AcceptanceInputs in;
  in.calibrated = &calibrated;
  in.nominal = &nominal;
  EXPECT_EQ(AcceptanceOf(in).checks[2].status, CheckStatus::kFailed);
  in.no_nominal_reason = "the set names no hand-eye transform";
  const AcceptanceCheck check = AcceptanceOf(in).checks[2];
  EXPECT_EQ(check.name, "beats_nominal_heldout");
  EXPECT_EQ(check.status, CheckStatus::kNotAvailable);
  EXPECT_NE(check.sentence.find("the set names no hand-eye transform"), std::string::npos) << check.sentence;
}

}  // namespace
}  // namespace selfcal::calibration

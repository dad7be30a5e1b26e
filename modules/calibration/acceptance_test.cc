#include "calibration/acceptance.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_robots.h"

namespace selfcal::calibration {
namespace {

// A held-out figure of verification poses with the given RMS per coordinate (10 dots each).
HeldOutReprojection Figures(const std::vector<double>& rms_px) {
  HeldOutReprojection h;
  h.ok = true;
  double sum2 = 0;
  for (size_t p = 0; p < rms_px.size(); ++p) {
    HeldOutFigure f;
    f.pose_id = "v" + std::to_string(p);
    f.num_residuals = 10;
    f.dof = 20;
    f.rms_px = rms_px[p];
    h.poses.push_back(f);
    sum2 += rms_px[p] * rms_px[p];
  }
  h.overall.num_residuals = 10 * static_cast<int>(rms_px.size());
  h.overall.dof = 2 * h.overall.num_residuals;
  h.overall.rms_px = std::sqrt(sum2 / rms_px.size());
  return h;
}

const AcceptanceCheck& Check(const Acceptance& a, const std::string& name) {
  for (const AcceptanceCheck& c : a.checks) {
    if (c.name == name) return c;
  }
  static const AcceptanceCheck none;
  ADD_FAILURE() << "no check " << name;
  return none;
}

// A nominal model that is already good: the calibrated one slightly worse on average, but by less than the
// spread between poses, is not significantly worse; consistently worse on every pose, it is refused.
TEST(Acceptance, ACalibrationNotSignificantlyWorseThanAGoodNominalModelPasses) {
  const HeldOutReprojection nominal = Figures({0.50, 0.80, 0.40, 0.90, 0.60, 0.70});
  const HeldOutReprojection close = Figures({0.60, 0.70, 0.50, 0.85, 0.65, 0.72});
  AcceptanceInputs in;
  in.calibrated = &close;
  in.nominal = &nominal;
  const AcceptanceCheck& passed = Check(AcceptanceOf(in), "beats_nominal_heldout");
  EXPECT_EQ(passed.status, CheckStatus::kPassed) << passed.sentence;
  EXPECT_NE(passed.sentence.find("not significantly worse"), std::string::npos) << passed.sentence;

  const HeldOutReprojection worse = Figures({0.60, 0.90, 0.50, 1.00, 0.70, 0.80});
  in.calibrated = &worse;
  const AcceptanceCheck& failed = Check(AcceptanceOf(in), "beats_nominal_heldout");
  EXPECT_EQ(failed.status, CheckStatus::kFailed) << failed.sentence;
  EXPECT_NE(failed.sentence.find("worse than the nominal model's"), std::string::npos) << failed.sentence;
}

// Two poses cannot tell a spread: a calibrated model not below the nominal one is refused, as before.
TEST(Acceptance, TooFewVerificationPosesToTestAreRefusedWhenNotBetter) {
  const HeldOutReprojection nominal = Figures({0.50, 0.80});
  const HeldOutReprojection worse = Figures({0.55, 0.80});
  AcceptanceInputs in;
  in.calibrated = &worse;
  in.nominal = &nominal;
  const AcceptanceCheck& c = Check(AcceptanceOf(in), "beats_nominal_heldout");
  EXPECT_EQ(c.status, CheckStatus::kFailed) << c.sentence;
  EXPECT_NE(c.sentence.find("too few"), std::string::npos) << c.sentence;
}

// The held-out checks that make a model tested, and the ones that do not.
TEST(Acceptance, OnlyAHeldOutCheckMakesAModelTested) {
  Acceptance a;
  a.checks = {{"plausible_corrections", CheckStatus::kPassed, ""}, {"heldout_test", CheckStatus::kNotAvailable, ""}};
  EXPECT_TRUE(a.Passed());
  EXPECT_FALSE(a.HeldOutTested());
  a.checks.push_back({"cross_validation_test", CheckStatus::kPassed, ""});
  EXPECT_TRUE(a.HeldOutTested());
}

// Check distances a set gives but could not measure (no verification pose to triangulate them from) are
// said to be there, with the reason, not called absent; a set without any says so.
TEST(Acceptance, UnmeasuredCheckDistancesSayWhy) {
  AcceptanceInputs in;
  const VerificationSummary none;
  in.distances_calibrated = &none;
  in.distances_nominal = &none;
  EXPECT_EQ(Check(AcceptanceOf(in), "beats_nominal_distances").sentence, "no check distances in the set");
  in.no_distances_reason = "the set's 1 check distance(s) are measured on verification poses, and it names none";
  const Acceptance acceptance = AcceptanceOf(in);
  const AcceptanceCheck& check = Check(acceptance, "beats_nominal_distances");
  EXPECT_EQ(check.status, CheckStatus::kNotAvailable);
  EXPECT_EQ(check.sentence, in.no_distances_reason);
}

// The yardstick against the description: every free length of the PUMA scaled by 0.955 (a 198.252 mm
// yardstick typed as 189.3 mm) is a factor of 0.955 exactly, refused; 0.3 % is a real arm's, passed; a
// deviation inside 3 sigma of a poorly determined scale refuses nothing.
TEST(Acceptance, TheYardstickIsCheckedAgainstTheDescriptionsLengths) {
  const RobotModel robot = selfcal::testing::Puma560();
  const KinematicParameters params(robot.num_joints());
  bundle::BundleReport b;
  b.rho = KinematicParameters::Nominal(robot);
  for (int i = 0; i < params.size(); ++i) {
    if (params.kind(i) == ParameterKind::kLength && std::abs(b.rho[i]) >= kMinScaleLengthM) b.free_indices.push_back(i);
  }
  ASSERT_GE(b.free_indices.size(), 3u);
  b.free_indices.push_back(params.IndexOf("j2.alpha"));  // an angle: no part of the scale
  const int free = static_cast<int>(b.free_indices.size());
  b.covariance_available = true;
  b.covariance_free = Eigen::MatrixXd::Identity(free + 1, free + 1) * 1e-8;  // + f_x; 0.1 mm per length
  auto scaled = [&](double factor) {
    bundle::BundleReport out = b;
    for (int i : b.free_indices) {
      if (params.kind(i) == ParameterKind::kLength) out.rho[i] *= factor;
    }
    out.rho[params.IndexOf("j2.alpha")] += 0.3;
    return out;
  };
  const YardstickScale wrong = YardstickScaleOf(robot, scaled(0.955), 1);
  ASSERT_TRUE(wrong.available) << wrong.reason;
  EXPECT_NEAR(wrong.scale, 0.955, 1e-12);
  EXPECT_GT(wrong.stddev, 0);
  EXPECT_LT(wrong.stddev, 1e-3);
  AcceptanceInputs in;
  in.yardstick_scale = &wrong;
  const AcceptanceCheck& refused = Check(AcceptanceOf(in), "yardstick_scale");
  EXPECT_EQ(refused.status, CheckStatus::kFailed) << refused.sentence;
  EXPECT_TRUE(refused.decisive);
  EXPECT_NE(refused.sentence.find("-4.50 % off: check the yardstick's length and its two dot ids"), std::string::npos)
      << refused.sentence;
  const YardstickScale right = YardstickScaleOf(robot, scaled(1.003), 1);
  in.yardstick_scale = &right;
  EXPECT_EQ(Check(AcceptanceOf(in), "yardstick_scale").status, CheckStatus::kPassed);
  YardstickScale uncertain = wrong;
  uncertain.stddev = 0.02;
  in.yardstick_scale = &uncertain;
  EXPECT_EQ(Check(AcceptanceOf(in), "yardstick_scale").status, CheckStatus::kPassed);
  const YardstickScale none = YardstickScaleOf(robot, scaled(0.955), 0);
  in.yardstick_scale = &none;
  EXPECT_FALSE(none.available);
  EXPECT_EQ(Check(AcceptanceOf(in), "yardstick_scale").status, CheckStatus::kNotAvailable);
}


// A held-out statistic far below its distribution (the residuals smaller than the stated noise says: a noise
// stated 5x too large gives about 1/25 of the degrees of freedom) passes, and the sentence says the test was
// lenient; one near its degrees of freedom, or above its 0.1 % point, does not say so.
TEST(Acceptance, AStatisticFarBelowItsDistributionSaysTheTestIsLenient) {
  HeldOutReprojection held = Figures({0.1, 0.1});
  HeldOutFigure figure = held.overall;
  figure.dof = 574;
  figure.chi_square_limit = ChiSquareQuantile(0.95, figure.dof);
  figure.test_passed = true;
  AcceptanceInputs in;
  in.calibrated = &held;
  in.test_at_stated_noise = &figure;
  in.stated_noise_px = 0.5;
  const double low = ChiSquareQuantile(1e-3, figure.dof);
  ASSERT_GT(low, 400);  // about 475 at 574 dof
  for (double chi_square : {574.0 / 25, low - 1.0, low + 1.0, 574.0}) {
    figure.chi_square = chi_square;
    figure.p_value = ChiSquareUpperTail(chi_square, figure.dof);
    const AcceptanceCheck& c = Check(AcceptanceOf(in), "heldout_test");
    EXPECT_EQ(c.status, CheckStatus::kPassed) << c.sentence;
    EXPECT_EQ(c.sentence.find("lenient") != std::string::npos, chi_square < low) << chi_square << ": " << c.sentence;
  }
}

}  // namespace
}  // namespace selfcal::calibration

// The calibrated model as a DH table in the user's convention: exact round trips where expressible, the
// reasons and their cost where not.
#include <random>

#include <gtest/gtest.h>

#include "kinematics/dh_table.h"
#include "support/perturbed_model.h"
#include "support/test_robots.h"

namespace selfcal {
namespace {

using testing::Puma560;

RobotModel Perturbed(const RobotModel& nominal, bool with_beta, std::uint64_t seed) {
  return testing::PerturbedModel(nominal, 2e-3, DegToRad(0.2), with_beta, seed);
}

double WorstFlangeDifference(const RobotModel& a, const RobotModel& b, int samples) {
  std::mt19937_64 rng(5);
  const Eigen::VectorXd rho_a = KinematicParameters::Nominal(a), rho_b = KinematicParameters::Nominal(b);
  double worst = 0;
  Eigen::VectorXd q(a.num_joints());
  for (int s = 0; s < samples; ++s) {
    for (int j = 0; j < q.size(); ++j) q[j] = std::uniform_real_distribution<double>(-3, 3)(rng);
    for (const auto& [x, y] : {std::pair{BaseFromFlange(a, rho_a, q), BaseFromFlange(b, rho_b, q)},
                               std::pair{BaseFromCam(a, rho_a, q), BaseFromCam(b, rho_b, q)}}) {
      const PoseDifference d = ComparePoses(x, y);
      worst = std::max({worst, d.position_m, d.rotation_rad});
    }
  }
  return worst;
}

TEST(DhTable, StandardRoundTripOfACalibratedPumaIsExact) {
  const RobotModel calibrated = Perturbed(Puma560(), /*with_beta=*/false, 1);
  const DhExpression dh = ExpressAsDh(calibrated, "standard");
  ASSERT_TRUE(dh.exact) << (dh.losses.empty() ? "" : dh.losses[0]);
  EXPECT_EQ(dh.table.convention, DhConvention::kStandard);
  EXPECT_LE(WorstFlangeDifference(calibrated, ModelOfDhTable("puma", dh.table), 500), 1e-12);
}

TEST(DhTable, ModifiedAndHayatiRoundTripsAreExact) {
  RobotModel modified = Perturbed(Puma560(), false, 2);
  modified.link_n_from_flange = Rigid3(RotY(0.3) * RotZ(-0.2), Eigen::Vector3d(0.01, -0.02, 0.03));
  const DhExpression dh = ExpressAsDh(modified, "modified");
  ASSERT_TRUE(dh.exact);
  EXPECT_LE(WorstFlangeDifference(modified, ModelOfDhTable("m", dh.table), 500), 1e-12);
  const RobotModel hayati = Perturbed(Puma560(), true, 3);
  const DhExpression h = ExpressAsDh(hayati, "modified_hayati");
  ASSERT_TRUE(h.exact);
  EXPECT_LE(WorstFlangeDifference(hayati, ModelOfDhTable("h", h.table), 500), 1e-12);
}

TEST(DhTable, ABetaIsNotExpressibleAndItsCostIsSaid) {
  RobotModel calibrated = Perturbed(Puma560(), false, 4);
  calibrated.links[2].beta = DegToRad(0.05);  // the tilt between the PUMA's parallel axes 2 and 3
  for (const char* convention : {"standard", "modified"}) {
    const DhExpression dh = ExpressAsDh(calibrated, convention);
    EXPECT_FALSE(dh.exact) << convention;
    ASSERT_EQ(dh.losses.size(), 1u) << convention;
    EXPECT_NE(dh.losses[0].find("j3.beta = 0.05 deg"), std::string::npos) << dh.losses[0];
    EXPECT_NE(dh.losses[0].find("axes 2 and 3"), std::string::npos) << dh.losses[0];
    // 0.05 deg about an axis ~0.45 m from the flange: a few tenths of a mm, and at most 0.05 deg.
    EXPECT_GT(dh.dropped_position_m, 1e-4) << convention;
    EXPECT_LT(dh.dropped_position_m, 1.2e-3) << convention;
    EXPECT_NEAR(dh.dropped_rotation_rad, DegToRad(0.05), DegToRad(0.01)) << convention;
  }
}

TEST(DhTable, StandardNeedsAFlangeTransformOfTxRx) {
  RobotModel calibrated = Perturbed(Puma560(), false, 6);
  calibrated.link_n_from_flange = Rigid3(RotY(0.1), Eigen::Vector3d(0, 0, 0.05));
  const DhExpression dh = ExpressAsDh(calibrated, "standard");
  EXPECT_FALSE(dh.exact);
  ASSERT_EQ(dh.losses.size(), 1u);
  EXPECT_NE(dh.losses[0].find("link_n_from_flange is not Tx(a) Rx(alpha)"), std::string::npos);
  EXPECT_TRUE(ExpressAsDh(calibrated, "modified").exact);
}

}  // namespace
}  // namespace selfcal

#include "identification/rank_selection.h"

#include <cmath>
#include <random>

#include <Eigen/QR>
#include <gtest/gtest.h>

namespace selfcal::identification {
namespace {

// Three parameters seen through 200 whitened rows: a and b independent, c = a + eps * (its own direction).
// Given a (and b), c is determined only through its own part: std(c | a, b) = 1 / (eps |own|).
Eigen::MatrixXd NearlyDependent(double eps, Eigen::VectorXd* own) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd j(200, 3);
  for (int r = 0; r < j.rows(); ++r) {
    j(r, 0) = n(rng);
    j(r, 1) = n(rng);
  }
  Eigen::VectorXd u(200);
  for (int r = 0; r < u.size(); ++r) u[r] = n(rng);
  // The part of u orthogonal to a and b, so that the conditional std is known exactly.
  const Eigen::MatrixXd ab = j.leftCols(2);
  u -= ab * (ab.colPivHouseholderQr().solve(u));
  *own = u;
  j.col(2) = j.col(0) + eps * u;
  return j;
}

TEST(FindWeakColumns, AColumnDeterminedWorseThanItsToleranceGivenTheEarlierOnesIsWeakWithItsPartner) {
  Eigen::VectorXd own;
  const double eps = 1e-3;
  const Eigen::MatrixXd j = NearlyDependent(eps, &own);
  const double expected_std = 1.0 / (eps * own.norm());
  const std::vector<std::string> names = {"j2.d", "j3.a", "j4.d"};
  Eigen::VectorXd tolerance = Eigen::VectorXd::Constant(3, expected_std * 0.5);
  std::vector<WeakColumn> weak = FindWeakColumns(j, {0, 1, 2}, tolerance, names);
  ASSERT_EQ(weak.size(), 1u);
  EXPECT_EQ(weak[0].column, 2);
  EXPECT_NEAR(weak[0].conditional_std, expected_std, 1e-9 * expected_std);
  EXPECT_EQ(weak[0].tolerance, tolerance[2]);
  // c trades off with a (c - a is what the data see), not with b.
  EXPECT_NE(weak[0].combination.find("j4.d"), std::string::npos) << weak[0].combination;
  EXPECT_NE(weak[0].combination.find("j2.d"), std::string::npos) << weak[0].combination;
  EXPECT_EQ(weak[0].combination.find("j3.a"), std::string::npos) << weak[0].combination;

  // A tolerance above the conditional std keeps it; a tolerance of 0 never makes a column weak.
  tolerance[2] = expected_std * 2;
  EXPECT_TRUE(FindWeakColumns(j, {0, 1, 2}, tolerance, names).empty());
  tolerance.setZero();
  EXPECT_TRUE(FindWeakColumns(j, {0, 1, 2}, tolerance, names).empty());
}

TEST(FindWeakColumns, TheOrderDecidesWhichOfTwoPartnersIsHeld) {
  Eigen::VectorXd own;
  const Eigen::MatrixXd j = NearlyDependent(1e-3, &own);
  const std::vector<std::string> names = {"a", "b", "c"};
  const Eigen::VectorXd tolerance = Eigen::VectorXd::Constant(3, 1.0);
  // c first: then a is the one determined only through c's own part.
  const std::vector<WeakColumn> weak = FindWeakColumns(j, {2, 1, 0}, tolerance, names);
  ASSERT_EQ(weak.size(), 1u);
  EXPECT_EQ(weak[0].column, 0);
}

TEST(FindWeakColumns, AWeakColumnJoinsNoBasisSoALaterIndependentColumnStaysFree) {
  Eigen::VectorXd own;
  Eigen::MatrixXd j = NearlyDependent(1e-3, &own);
  j.conservativeResize(Eigen::NoChange, 4);
  // d = c - a + its own strong direction: had c entered the basis, d would look determined through c.
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::VectorXd w(j.rows());
  for (int r = 0; r < w.size(); ++r) w[r] = n(rng);
  j.col(3) = w;
  const Eigen::VectorXd tolerance = Eigen::VectorXd::Constant(4, 1.0);
  const std::vector<WeakColumn> weak = FindWeakColumns(j, {0, 1, 2, 3}, tolerance, {"a", "b", "c", "d"});
  ASSERT_EQ(weak.size(), 1u);
  EXPECT_EQ(weak[0].column, 2);
}

// A problem with no rows (every dot dropped) or only zero columns keeps nothing, names every column as
// dependent, each alone, and does not crash (an empty QR read past its ends: calibrate died with SIGSEGV).
TEST(SelectColumns, NothingToKeepMakesEveryColumnDependentAlone) {
  const std::vector<std::string> names = {"a", "b", "c"};
  for (const Eigen::MatrixXd& j : std::vector<Eigen::MatrixXd>{Eigen::MatrixXd(0, 3), Eigen::MatrixXd::Zero(5, 3)}) {
    const RankSelection r = SelectColumns(j, {0, 1, 2}, 1e-10, names);
    EXPECT_TRUE(r.kept.empty());
    EXPECT_EQ(r.dependent, (std::vector<int>{0, 1, 2}));
    ASSERT_EQ(r.null_combinations.size(), 3u);
  }
  Eigen::VectorXd tolerance = Eigen::VectorXd::Ones(3);
  const std::vector<WeakColumn> weak = FindWeakColumns(Eigen::MatrixXd::Zero(5, 3), {0, 1, 2}, tolerance, names);
  EXPECT_EQ(weak.size(), 3u);
}

}  // namespace
}  // namespace selfcal::identification

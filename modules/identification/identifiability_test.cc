#include "identification/identifiability.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "identification/test_util.h"
#include "kinematics/autodiff_jacobian.h"
#include "support/test_robots.h"

namespace selfcal::identification {
namespace {

using selfcal::testing::Puma560;
using selfcal::testing::Ur5e;

// The relative-pose residual written independently of the module (double only, Eigen's log).
Eigen::VectorXd Residuals(const RobotModel& model, const Eigen::VectorXd& rho,
                          const std::vector<Eigen::VectorXd>& poses, int reference, const std::vector<Rigid3>& measured,
                          double sp, double sr) {
  Eigen::VectorXd r(6 * (poses.size() - 1));
  const Rigid3 ref_from_base = BaseFromCam(model, rho, poses[reference]).Inverse();
  int row = 0;
  for (int i = 0; i < static_cast<int>(poses.size()); ++i) {
    if (i == reference) continue;
    const Rigid3 predicted = ref_from_base * BaseFromCam(model, rho, poses[i]);
    r.segment<3>(row) = LogSO3(predicted.rotation.transpose() * measured[i].rotation) / sr;
    r.segment<3>(row + 3) = (predicted.translation - measured[i].translation) / sp;
    row += 6;
  }
  return r;
}

void Print(const std::string& title, const IdentifiabilityReport& report) {
  std::cout << title << ": " << report.rank << " identifiable of " << report.num_parameters << ", "
            << report.fixed_indices.size() << " fixed, condition number " << report.condition_number << "\n  fixed:";
  for (const std::string& name : report.fixed_names) std::cout << " " << name;
  std::cout << "\n  null combinations:\n";
  for (const std::string& c : report.null_combinations) std::cout << "    " << c << "\n";
}

TEST(Identifiability, JacobianMatchesNumericDifferentiation) {
  for (const RobotModel& model : {Puma560(), Ur5e()}) {
    std::mt19937 rng(11);
    std::normal_distribution<double> g(0.0, 0.01);
    Eigen::VectorXd rho = KinematicParameters::Nominal(model);
    for (int i = 0; i < rho.size(); ++i) rho[i] += g(rng);
    const auto poses = testing::RandomPoses(model, 6, &rng);
    const int reference = 2;
    const double sp = 1e-3, sr = 1e-4;
    std::vector<Rigid3> measured(poses.size());
    for (size_t i = 0; i < poses.size(); ++i) {
      measured[i] = testing::TrueRelativePose(model, rho, poses[reference], poses[i]);
    }
    const Eigen::MatrixXd analytic = RelativePoseJacobian(model, rho, poses, reference, sp, sr);
    auto f = [&](const double* x, double* y) {
      const Eigen::VectorXd r =
          Residuals(model, Eigen::Map<const Eigen::VectorXd>(x, rho.size()), poses, reference, measured, sp, sr);
      Eigen::Map<Eigen::VectorXd>(y, r.size()) = r;
    };
    const Eigen::MatrixXd numeric = NumericJacobian(f, rho, static_cast<int>(analytic.rows()));
    ASSERT_EQ(analytic.rows(), 6 * 5);
    ASSERT_EQ(analytic.cols(), model.num_parameters());
    const double scale = analytic.cwiseAbs().maxCoeff();
    EXPECT_GT(scale, 1e3);
    EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-7 * scale) << model.name;
  }
}

struct Expected {
  int rank;
  std::vector<std::string> fixed;
};

std::vector<std::string> CommonFixed() {
  return {"base.tx",  "base.ty", "base.tz", "base.rx",  "base.ry", "base.rz",
          "j1.alpha", "j1.a",    "j1.beta", "j1.theta", "j1.d",    "j2.beta"};
}

// Rank and fixed set at 15 random poses for three seeds: generic poses must give the same structure.
void CheckStructure(const RobotModel& model, bool scale_known, const Expected& expected) {
  for (unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    const auto poses = testing::RandomPoses(model, 15, &rng);
    IdentifiabilityOptions options;
    options.scale_known = scale_known;
    const auto start = std::chrono::steady_clock::now();
    const IdentifiabilityReport report =
        AnalyzeIdentifiability(model, KinematicParameters::Nominal(model), poses, 0, options);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (seed == 1) std::cout << "analysis took " << ms << " ms\n";
    if (seed == 1) Print(model.name + (scale_known ? ", scale known" : ", scale unknown"), report);
    EXPECT_EQ(report.num_parameters, model.num_parameters());
    EXPECT_EQ(report.rank, expected.rank) << model.name << " seed " << seed;
    EXPECT_EQ(static_cast<int>(report.free_indices.size()), report.rank);
    EXPECT_EQ(report.free_indices.size() + report.fixed_indices.size(), static_cast<size_t>(model.num_parameters()));
    std::vector<std::string> fixed = report.fixed_names, want = expected.fixed;
    std::sort(fixed.begin(), fixed.end());
    std::sort(want.begin(), want.end());
    EXPECT_EQ(fixed, want) << model.name << " seed " << seed;
    // One named direction per fixed parameter.
    EXPECT_EQ(report.null_combinations.size(), report.fixed_indices.size());
    EXPECT_TRUE(std::isfinite(report.condition_number));
    EXPECT_GE(report.condition_number, 1.0);
    EXPECT_LT(report.condition_number, 1e3) << model.name << " seed " << seed;
    EXPECT_EQ(report.singular_values.size(), model.num_parameters() + (scale_known ? 0 : 1));
    const bool has_scale = std::any_of(report.null_combinations.begin(), report.null_combinations.end(),
                                       [](const std::string& c) { return c.find("scale") != std::string::npos; });
    EXPECT_EQ(has_scale, !scale_known);
  }
}

TEST(Identifiability, Puma560StructureScaleKnown) {
  Expected e{24, CommonFixed()};
  for (const char* name : {"j3.d", "j4.beta", "j5.beta", "j6.beta", "j6.theta", "j6.d"}) e.fixed.push_back(name);
  CheckStructure(Puma560(), true, e);
}

TEST(Identifiability, Puma560StructureScaleUnknown) {
  // The global scale makes one more length dependent: with the PUMA's lengths (a3, d4, d3/d2, camera)
  // the last one taken in the selection order, d4.
  Expected e{23, CommonFixed()};
  for (const char* name : {"j3.d", "j4.beta", "j4.d", "j5.beta", "j6.beta", "j6.theta", "j6.d"}) {
    e.fixed.push_back(name);
  }
  CheckStructure(Puma560(), false, e);
}

TEST(Identifiability, Ur5eStructureScaleKnown) {
  // Three parallel axes (2, 3, 4): one d for the three, betas kept on joints 3 and 4.
  Expected e{24, CommonFixed()};
  for (const char* name : {"j3.d", "j4.d", "j5.beta", "j6.beta", "j6.theta", "j6.d"}) e.fixed.push_back(name);
  CheckStructure(Ur5e(), true, e);
}

TEST(Identifiability, Ur5eStructureScaleUnknown) {
  Expected e{23, CommonFixed()};
  for (const char* name : {"j3.d", "j4.d", "j5.beta", "j5.d", "j6.beta", "j6.theta", "j6.d"}) e.fixed.push_back(name);
  CheckStructure(Ur5e(), false, e);
}

TEST(Identifiability, NamesTheParallelPairCombination) {
  std::mt19937 rng(5);
  const RobotModel puma = Puma560();
  const auto poses = testing::RandomPoses(puma, 15, &rng);
  const IdentifiabilityReport report =
      AnalyzeIdentifiability(puma, KinematicParameters::Nominal(puma), poses, 0, IdentifiabilityOptions());
  const auto& c = report.null_combinations;
  // A null direction has no sign: either wording names the same combination.
  const bool named = std::find(c.begin(), c.end(), "0.71 j2.d - 0.71 j3.d") != c.end() ||
                     std::find(c.begin(), c.end(), "0.71 j3.d - 0.71 j2.d") != c.end();
  EXPECT_TRUE(named) << ::testing::PrintToString(c);
  EXPECT_NE(std::find(c.begin(), c.end(), "1.00 base.tx"), c.end());
  // Deterministic: the same input gives the same words.
  const IdentifiabilityReport again =
      AnalyzeIdentifiability(puma, KinematicParameters::Nominal(puma), poses, 0, IdentifiabilityOptions());
  EXPECT_EQ(again.null_combinations, report.null_combinations);
  EXPECT_EQ(again.free_indices, report.free_indices);
}

TEST(Identifiability, PosesMovingOnlyTheWristSeeLess) {
  // Only joints 5 and 6 move: the rest of the arm is a rigid base as far as the data can tell.
  const RobotModel puma = Puma560();
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::VectorXd> poses;
  for (int k = 0; k < 15; ++k) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
    q[4] = u(rng);
    q[5] = u(rng);
    poses.push_back(q);
  }
  const IdentifiabilityReport report =
      AnalyzeIdentifiability(puma, KinematicParameters::Nominal(puma), poses, 0, IdentifiabilityOptions());
  Print("puma560, wrist-only poses", report);
  EXPECT_LT(report.rank, 24);
  EXPECT_EQ(std::count(report.free_names.begin(), report.free_names.end(), "j3.a"), 0);
}

}  // namespace
}  // namespace selfcal::identification

// Seeded Monte Carlo checks of the bundle adjustment's statistics: coverage of the reported sigmas,
// efficiency against the Cramer-Rao bound, and the gain over the paper's pipeline on the same data.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "bundle/bundle_adjustment.h"
#include "bundle/bundle_test_util.h"
#include "calibration/paper_pipeline.h"

namespace selfcal::bundle {
namespace {

using testing::Truth;
using testing::VerificationPoseErrors;
using testing::World;

// Pooled over runs: errors of the free parameters and f_x, coverage of +-2 sigma (reported), verification
// pose and 3-D distance errors, and the same figures of the paper pipeline on a subset of the runs.
struct Tally {
  std::vector<double> sum_sq;  // per free parameter, then f_x
  int runs = 0, intervals = 0, covered = 0;
  double pose_position_sq = 0, pose_rotation_sq = 0, distance_sq = 0;
  int pose_count = 0, distance_count = 0;
  double paper_pose_position_sq = 0, paper_pose_rotation_sq = 0, paper_distance_sq = 0;
  double bundle_pose_position_sq_same_runs = 0, bundle_distance_sq_same_runs = 0;
  int paper_pose_count = 0, paper_distance_count = 0, paper_runs = 0;
  std::vector<double> pose_ratio_per_run;  // BA / paper, verification pose position RMS of one run
  double seconds = 0;
  int iterations = 0;
};

double Rms(double sum_sq, int count) { return count > 0 ? std::sqrt(sum_sq / count) : 0.0; }

void AddRun(const sim::SimResult& world, const ObservationSet& obs, bool with_paper, Tally* t) {
  const BundleReport r = RunBundleAdjustment(obs, KinematicParameters::Nominal(obs.robot), obs.camera.fx_px, {});
  ASSERT_EQ(r.outcome, Outcome::kConverged) << r.message;
  ASSERT_TRUE(r.covariance_available) << r.covariance_message;
  ASSERT_EQ(r.free_indices, world.truth.perturbed_indices);
  const int nf = static_cast<int>(r.free_indices.size());
  t->sum_sq.resize(nf + 1, 0.0);
  for (int k = 0; k <= nf; ++k) {
    const double error = k < nf ? r.rho[r.free_indices[k]] - world.truth.rho_true[r.free_indices[k]]
                                : r.fx_px - world.truth.camera_true.fx_px;
    const double sigma = k < nf ? r.stddev[r.free_indices[k]] : r.fx_stddev;
    t->sum_sq[k] += error * error;
    ++t->intervals;
    t->covered += std::abs(error) <= 2 * sigma ? 1 : 0;
  }
  ++t->runs;
  t->seconds += r.seconds;
  t->iterations += r.iterations;
  const testing::PoseErrors pose = VerificationPoseErrors(world, obs, obs.robot, r.rho);
  double run_pose_sq = 0;
  for (size_t k = 0; k < pose.position_m.size(); ++k) {
    run_pose_sq += pose.position_m[k] * pose.position_m[k];
    t->pose_rotation_sq += pose.rotation_rad[k] * pose.rotation_rad[k];
  }
  t->pose_position_sq += run_pose_sq;
  t->pose_count += static_cast<int>(pose.position_m.size());
  const std::vector<int> verification = obs.PosesWithRole(PoseRole::kVerification);
  const calibration::VerificationSummary distances =
      calibration::VerifyDistances(obs, verification, obs.robot, r.rho, r.fx_px, obs.check_distances);
  t->distance_sq += distances.rms_error_m * distances.rms_error_m * distances.num_ok;
  t->distance_count += distances.num_ok;
  if (!with_paper) return;
  const calibration::PaperPipelineReport paper = calibration::RunPaperPipeline(obs, calibration::PaperPipelineOptions());
  ASSERT_EQ(paper.outcome, calibration::Outcome::kSuccess) << paper.message;
  const testing::PoseErrors paper_pose = VerificationPoseErrors(world, obs, paper.calibrated_robot, paper.calibrated_rho);
  for (size_t k = 0; k < paper_pose.position_m.size(); ++k) {
    t->paper_pose_position_sq += paper_pose.position_m[k] * paper_pose.position_m[k];
    t->paper_pose_rotation_sq += paper_pose.rotation_rad[k] * paper_pose.rotation_rad[k];
  }
  t->paper_pose_count += static_cast<int>(paper_pose.position_m.size());
  double paper_run_sq = 0;
  for (double e : paper_pose.position_m) paper_run_sq += e * e;
  t->pose_ratio_per_run.push_back(std::sqrt(run_pose_sq / paper_run_sq));
  t->bundle_pose_position_sq_same_runs += run_pose_sq;
  const calibration::VerificationSummary& pd = paper.verification_calibrated;
  t->paper_distance_sq += pd.rms_error_m * pd.rms_error_m * pd.num_ok;
  t->paper_distance_count += pd.num_ok;
  t->bundle_distance_sq_same_runs += distances.rms_error_m * distances.rms_error_m * distances.num_ok;
  ++t->paper_runs;
}

// Prints the figures and checks coverage and the gain over the paper pipeline.
void Report(const char* label, const Tally& t) {
  const double coverage = static_cast<double>(t.covered) / t.intervals;
  const double bundle_pose_same = Rms(t.bundle_pose_position_sq_same_runs, t.paper_pose_count);
  const double paper_pose = Rms(t.paper_pose_position_sq, t.paper_pose_count);
  const double bundle_distance_same = Rms(t.bundle_distance_sq_same_runs, t.paper_distance_count);
  const double paper_distance = Rms(t.paper_distance_sq, t.paper_distance_count);
  std::vector<double> ratios = t.pose_ratio_per_run;
  std::sort(ratios.begin(), ratios.end());
  const double median_ratio = ratios.empty() ? 0.0 : ratios[ratios.size() / 2];
  std::cout << "[ figure ] " << label << ": " << t.runs << " runs, coverage of +-2 sigma " << coverage << " ("
            << t.intervals << " intervals); BA " << t.seconds / t.runs * 1e3 << " ms and "
            << static_cast<double>(t.iterations) / t.runs << " iterations per solve\n"
            << "[ figure ] " << label << ": verification relative pose RMS error BA "
            << Rms(t.pose_position_sq, t.pose_count) * 1e3 << " mm / " << Rms(t.pose_rotation_sq, t.pose_count)
            << " rad; 3-D distance RMS error BA " << Rms(t.distance_sq, t.distance_count) * 1e3 << " mm\n"
            << "[ figure ] " << label << ": on " << t.paper_runs << " runs, paper pipeline pose " << paper_pose * 1e3
            << " mm / " << Rms(t.paper_pose_rotation_sq, t.paper_pose_count) << " rad vs BA " << bundle_pose_same * 1e3
            << " mm (ratio BA/paper " << bundle_pose_same / paper_pose << "); 3-D distance paper "
            << paper_distance * 1e3 << " mm vs BA " << bundle_distance_same * 1e3 << " mm (ratio "
            << bundle_distance_same / paper_distance << "); median per-run pose ratio BA/paper " << median_ratio
            << ", worst " << (ratios.empty() ? 0.0 : ratios.back()) << "\n";
  EXPECT_GE(coverage, 0.90);
  EXPECT_LE(coverage, 0.98);
  EXPECT_LT(bundle_pose_same, 0.5 * paper_pose);
  EXPECT_LT(median_ratio, 0.5);
  EXPECT_LT(bundle_distance_same, 0.9 * paper_distance);
}

// One world, 200 noise draws at 0.2 px: the BA's RMS error per free parameter against the bound.
TEST(BundleMonteCarlo, EfficientAtTheCramerRaoBoundWithCalibratedSigmas) {
  const double noise = 0.2;
  const sim::SimResult world = World(noise, 1, 1);
  const CramerRaoReport bound = BundleCramerRao(world.observations, Truth(world), noise, BundleOptions());
  ASSERT_TRUE(bound.ok) << bound.message;
  ASSERT_EQ(bound.free_indices, world.truth.perturbed_indices);
  Tally tally;
  const int runs = 200;
  for (int run = 0; run < runs; ++run) {
    const ObservationSet obs = sim::Reobserve(world, noise, 5000 + run);
    AddRun(world, obs, run < 15, &tally);
    if (::testing::Test::HasFatalFailure()) return;
  }
  const KinematicParameters params(6);
  const int nf = static_cast<int>(bound.free_indices.size());
  double min_ratio = 1e9, max_ratio = 0, sum_ratio = 0;
  for (int k = 0; k <= nf; ++k) {
    const double rms = std::sqrt(tally.sum_sq[k] / runs);
    const double crb = k < nf ? bound.stddev[bound.free_indices[k]] : bound.fx_stddev;
    const double ratio = rms / crb;
    const std::string name = k < nf ? params.name(bound.free_indices[k]) : "fx";
    std::cout << "[ figure ]   " << name << ": MC RMS " << rms << ", bound " << crb << ", ratio " << ratio << "\n";
    // 200 runs: the RMS itself scatters by ~5 %; 20 % is four of those.
    EXPECT_GT(ratio, 0.8) << name;
    EXPECT_LT(ratio, 1.2) << name;
    min_ratio = std::min(min_ratio, ratio);
    max_ratio = std::max(max_ratio, ratio);
    sum_ratio += ratio;
  }
  const double mean_ratio = sum_ratio / (nf + 1);
  EXPECT_NEAR(mean_ratio, 1.0, 0.1);
  const double pose_rms = Rms(tally.pose_position_sq, tally.pose_count);
  const double rotation_rms = Rms(tally.pose_rotation_sq, tally.pose_count);
  std::cout << "[ figure ] noise 0.2 px, MC/bound ratio over " << nf + 1 << " parameters: mean " << mean_ratio
            << ", min " << min_ratio << ", max " << max_ratio << "\n"
            << "[ figure ] noise 0.2 px, verification relative pose bound " << bound.rms_position_bound_m * 1e3
            << " mm / " << bound.rms_orientation_bound_rad << " rad; MC " << pose_rms * 1e3 << " mm / "
            << rotation_rms << " rad (ratio " << pose_rms / bound.rms_position_bound_m << " / "
            << rotation_rms / bound.rms_orientation_bound_rad << ")\n";
  EXPECT_NEAR(pose_rms / bound.rms_position_bound_m, 1.0, 0.15);
  EXPECT_NEAR(rotation_rms / bound.rms_orientation_bound_rad, 1.0, 0.15);
  Report("noise 0.2 px, one world", tally);
}

// 100 different worlds (robot errors, f_x, scene) at 0.5 px.
TEST(BundleMonteCarlo, CoverageOverWorldsAtHalfAPixel) {
  const double noise = 0.5;
  Tally tally;
  for (int run = 0; run < 100; ++run) {
    const sim::SimResult world = World(noise, 100 + run, 100 + run);
    AddRun(world, world.observations, run < 15, &tally);
    if (::testing::Test::HasFatalFailure()) return;
  }
  Report("noise 0.5 px, 100 worlds", tally);
}

}  // namespace
}  // namespace selfcal::bundle

#include "simulation/study.h"

#include <gtest/gtest.h>

#include "sim/trajectory_generator.h"
#include "support/sim_worlds.h"
#include "support/test_robots.h"

namespace selfcal::simulation {
namespace {

void ExpectSameStat(const Stat& a, const Stat& b, const std::string& what) {
  ASSERT_EQ(a.values.size(), b.values.size()) << what;
  for (size_t k = 0; k < a.values.size(); ++k) EXPECT_EQ(a.values[k], b.values[k]) << what << "[" << k << "]";
}

// A study on 3 threads is the study on one, sample for sample and in the same order (the wall times
// apart): runs are seeded by their index and merged in run order. Three runs at 0.2 px, one of them
// through the rendered images, so that every kind of field is filled.
TEST(Study, ThreadsGiveTheSingleThreadedResults) {
  const RobotModel puma = testing::Puma560();
  const sim::GeneratedTrajectory arc = sim::MakeArcTrajectory(puma, sim::ArcTrajectoryOptions());
  ASSERT_TRUE(arc.ok) << arc.message;
  StudyOptions options;
  options.runs = 3;
  options.noise_levels_px = {0.2};
  options.with_opencv = false;
  options.sim.separation_dot_radius_m = options.rendered.dot_radius_m;
  options.rendered_levels = {{"img-I", 2, 0, 0.01}};
  options.jobs = 1;
  const StudyReport one = RunStudy(puma, {{"arc", arc.joints}}, options);
  options.jobs = 3;
  const StudyReport three = RunStudy(puma, {{"arc", arc.joints}}, options);
  ASSERT_EQ(one.cells.size(), 2u);
  ASSERT_EQ(three.cells.size(), one.cells.size());
  EXPECT_GT(one.identifiable_parameters, 0);
  EXPECT_EQ(three.identifiable_parameters, one.identifiable_parameters);
  EXPECT_EQ(three.fixed_parameters, one.fixed_parameters);
  EXPECT_EQ(three.bundle_free_parameters, one.bundle_free_parameters);
  EXPECT_EQ(three.bundle_fixed_parameters, one.bundle_fixed_parameters);
  for (size_t c = 0; c < one.cells.size(); ++c) {
    const StudyCell& a = one.cells[c];
    const StudyCell& b = three.cells[c];
    EXPECT_EQ(a.trajectory, b.trajectory);
    EXPECT_EQ(a.runs, 3);
    EXPECT_EQ(b.runs, a.runs);
    EXPECT_EQ(b.runs_failed, a.runs_failed);
    EXPECT_EQ(b.bundle_runs_failed, a.bundle_runs_failed);
    EXPECT_EQ(b.bundle_intervals, a.bundle_intervals);
    EXPECT_EQ(b.bundle_covered, a.bundle_covered);
    EXPECT_GT(a.position_mm.count(), 0);
    EXPECT_GT(a.bundle_error3d_mm.count(), 0);
    ExpectSameStat(a.position_mm, b.position_mm, a.trajectory + " position_mm");
    ExpectSameStat(a.orientation_1e4rad, b.orientation_1e4rad, a.trajectory + " orientation");
    ExpectSameStat(a.error3d_calibrated_mm, b.error3d_calibrated_mm, a.trajectory + " error3d");
    ExpectSameStat(a.bound_position_mm_fx_unknown, b.bound_position_mm_fx_unknown, a.trajectory + " bound");
    ExpectSameStat(a.bundle_position_mm, b.bundle_position_mm, a.trajectory + " bundle_position_mm");
    ExpectSameStat(a.bundle_error3d_mm, b.bundle_error3d_mm, a.trajectory + " bundle_error3d_mm");
    ExpectSameStat(a.bundle_predicted3d_mm, b.bundle_predicted3d_mm, a.trajectory + " bundle_predicted3d_mm");
    ExpectSameStat(a.bundle_bound3d_mm, b.bundle_bound3d_mm, a.trajectory + " bundle_bound3d_mm");
    ASSERT_EQ(a.bundle_parameter_error.size(), b.bundle_parameter_error.size());
    for (const auto& [name, stat] : a.bundle_parameter_error) {
      ExpectSameStat(stat, b.bundle_parameter_error.at(name), name);
    }
    EXPECT_EQ(a.centroids.matched, b.centroids.matched);
    EXPECT_EQ(a.centroids.vs_area_centroid_px, b.centroids.vs_area_centroid_px);
  }
  EXPECT_GT(one.cells[1].centroids.matched, 0);
}

// One run's cell appended to another's: counts add, samples follow in order, failures stop at five.
TEST(Study, CellAppendKeepsRunOrder) {
  StudyCell a, b;
  a.runs = 2;
  b.runs = 3;
  a.position_mm.values = {1, 2};
  b.position_mm.values = {3};
  a.bundle_parameter_error["d1"].values = {4};
  b.bundle_parameter_error["d1"].values = {5};
  b.bundle_parameter_error["a2"].values = {6};
  a.failures = {"f1", "f2", "f3", "f4"};
  b.failures = {"g1", "g2"};
  a.bundle_weak_held["j3.beta"] = 1;
  b.bundle_weak_held["j3.beta"] = 2;
  b.bundle_weak_held["j5.alpha"] = 1;
  a.bundle_runs_weak_held = 1;
  b.bundle_runs_weak_held = 2;
  a.bundle_runs_in_truths_gauge = 1;
  b.bundle_runs_in_truths_gauge = 1;
  b.bundle_length_error_mm.values = {7};
  a.Append(b);
  EXPECT_EQ(a.bundle_weak_held, (std::map<std::string, int>{{"j3.beta", 3}, {"j5.alpha", 1}}));
  EXPECT_EQ(a.bundle_runs_weak_held, 3);
  EXPECT_EQ(a.bundle_runs_in_truths_gauge, 2);
  EXPECT_EQ(a.bundle_length_error_mm.values, (std::vector<double>{7}));
  EXPECT_EQ(a.runs, 5);
  EXPECT_EQ(a.position_mm.values, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(a.bundle_parameter_error["d1"].values, (std::vector<double>{4, 5}));
  EXPECT_EQ(a.bundle_parameter_error["a2"].values, (std::vector<double>{6}));
  EXPECT_EQ(a.failures, (std::vector<std::string>{"f1", "f2", "f3", "f4", "g1"}));
}

// The PUMA 560's eye-to-hand cell (sim_world.h) on its eye-to-hand start, two runs: no paper pipeline rows and
// no failure counted for them; no noise gives the truth back; at 0.5 px the bundle holds j3.beta at the
// description in both runs (its std from these poses is beyond 0.5 deg), so neither run is scored against
// the truth parameter by parameter, while the relative poses are.
TEST(Study, EyeToHandLeavesThePaperOutAndCountsTheWeakHeld) {
  const testing::EyeToHandCell cell = testing::PumaEyeToHandCell();
  ASSERT_EQ(cell.start.size(), 25u);
  StudyOptions options;
  options.runs = 2;
  options.noise_levels_px = {0.0, 0.5};
  options.jobs = 2;
  const StudyReport study = RunStudy(cell.robot, {{"start", cell.start}}, options);
  EXPECT_EQ(study.configuration, CameraMount::kEyeToHand);
  EXPECT_FALSE(study.paper_pipeline_note.empty());
  EXPECT_EQ(study.identifiable_parameters, 0);
  EXPECT_EQ(study.bundle_free_parameters, 24);
  ASSERT_EQ(study.cells.size(), 2u);
  for (const StudyCell& c : study.cells) {
    EXPECT_EQ(c.runs_failed, 0) << c.noise_px;
    EXPECT_EQ(c.position_mm.count(), 0);
    EXPECT_EQ(c.bundle_runs_failed, 0) << c.noise_px;
  }
  const StudyCell& exact = study.cells[0];
  EXPECT_EQ(exact.bundle_runs_in_truths_gauge, 2);
  EXPECT_LT(exact.bundle_length_error_mm.Max(), 1e-6);
  EXPECT_LT(exact.bundle_angle_error_deg.Max(), RadToDeg(1e-9));
  const StudyCell& noisy = study.cells[1];
  EXPECT_EQ(noisy.bundle_weak_held.count("j3.beta") ? noisy.bundle_weak_held.at("j3.beta") : 0, 2);
  EXPECT_EQ(noisy.bundle_runs_weak_held, 2);
  EXPECT_EQ(noisy.bundle_runs_in_truths_gauge, 0);
  EXPECT_EQ(noisy.bundle_intervals, 0);
  EXPECT_TRUE(noisy.bundle_parameter_error.empty());
  EXPECT_EQ(noisy.bundle_position_mm.count(), 2 * 14);  // 15 identification poses, the first the reference
  EXPECT_GT(noisy.bundle_bound_position_mm.count(), 0);
}

}  // namespace
}  // namespace selfcal::simulation

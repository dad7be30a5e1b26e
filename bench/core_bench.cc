// Speed of the numerical core on the simulated PUMA 560: 25 poses x 80 dots (15 identification + 10
// verification), pixel noise 0.2 px.
#include <benchmark/benchmark.h>

#include "bundle/bundle_adjustment.h"
#include "calibration/bundle_stage.h"
#include "calibration/paper_pipeline.h"
#include "simulation/study.h"
#include "planning/planner.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "support/test_robots.h"

namespace selfcal {
namespace {

const sim::SimResult& World() {
  static const sim::SimResult world = [] {
    const RobotModel puma = testing::Puma560();
    sim::SimOptions options;
    options.pixel_noise_px = 0.2;
    return sim::Simulate(puma, sim::MakeArcTrajectory(puma, sim::ArcTrajectoryOptions()).joints, options);
  }();
  return world;
}

void BM_TwoViewPair80Dots(benchmark::State& state) {
  const ObservationSet& obs = World().observations;
  const Matches m = MatchById(obs.poses[0], obs.poses[10]);
  for (auto _ : state) {
    benchmark::DoNotOptimize(twoview::EstimateTwoView(twoview::TwoViewOptions(), obs.camera, m.pixels_a, m.pixels_b));
  }
}
BENCHMARK(BM_TwoViewPair80Dots)->Unit(benchmark::kMillisecond);

void BM_PaperPipeline25Poses80Dots(benchmark::State& state) {
  const ObservationSet& obs = World().observations;
  for (auto _ : state) {
    const calibration::PaperPipelineReport report = calibration::RunPaperPipeline(obs, calibration::PaperPipelineOptions());
    if (report.outcome != calibration::Outcome::kSuccess) state.SkipWithError(report.message.c_str());
  }
}
BENCHMARK(BM_PaperPipeline25Poses80Dots)->Unit(benchmark::kMillisecond);

// The bundle solve alone (screen refits and covariance included), started from the paper pipeline's result
// as calibration::RunBundleStage starts it; the paper pipeline runs once, outside the timed loop.
void BM_BundleAdjustment25Poses80Dots(benchmark::State& state) {
  const ObservationSet& obs = World().observations;
  const calibration::PaperPipelineReport paper = calibration::RunPaperPipeline(obs, calibration::PaperPipelineOptions());
  if (paper.outcome != calibration::Outcome::kSuccess) {
    state.SkipWithError(paper.message.c_str());
    return;
  }
  double fx_start = 0;
  const Eigen::VectorXd rho_start = calibration::BundleStartFromPaper(obs, paper, &fx_start);
  int iterations = 0;
  for (auto _ : state) {
    const bundle::BundleReport r = bundle::RunBundleAdjustment(obs, rho_start, fx_start, bundle::BundleOptions());
    if (r.outcome != bundle::Outcome::kConverged) state.SkipWithError(r.message.c_str());
    iterations = r.iterations;
  }
  state.counters["lm_iterations"] = iterations;
}
BENCHMARK(BM_BundleAdjustment25Poses80Dots)->Unit(benchmark::kMillisecond);

// The whole study at one noise level: paper pipeline and kinematic bundle adjustment per run; with
// with_opencv_and_bound = 1 also the OpenCV comparison and both Cramer-Rao bounds. jobs: the threads
// (1, or 0 = every core); the report is the same. Process CPU time and wall time.
void BM_Study200Runs(benchmark::State& state) {
  const RobotModel puma = testing::Puma560();
  const simulation::TrajectorySpec trajectory{"initial", sim::MakeArcTrajectory(puma, sim::ArcTrajectoryOptions()).joints};
  simulation::StudyOptions options;
  options.runs = 200;
  options.noise_levels_px = {0.2};
  options.with_opencv = state.range(0) != 0;
  options.with_bound = state.range(0) != 0;
  options.with_bundle = true;
  options.jobs = static_cast<int>(state.range(1));
  for (auto _ : state) benchmark::DoNotOptimize(simulation::RunStudy(puma, {trajectory}, options));
}
BENCHMARK(BM_Study200Runs)
    ->ArgNames({"with_opencv_and_bound", "jobs"})
    ->ArgsProduct({{0, 1}, {1, 0}})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Planning m = 25 poses (15 planned, 10 verification kept) on the PUMA 560 from the shipped initial arc, the
// simulated scene's dots as the rough dot positions, the CLI's default constraints (image margin 5 px).
// The paper's planner took about an hour (MATLAB, 150 MHz). Includes the repair of the arc's intersecting
// axes from the candidate pool.
void BM_Plan25Poses(benchmark::State& state) {
  planning::PlanningProblem problem;
  problem.robot = World().truth.nominal;
  problem.camera = World().observations.camera;
  problem.scene = planning::Scene::FromDots(World().truth.dots_in_base);
  problem.constraints.image_margin_px = 5.0;
  std::vector<Eigen::VectorXd> start;
  for (const PoseObservation& p : World().observations.poses) start.push_back(p.joints_rad);
  planning::PlannerOptions options;
  options.criterion = static_cast<planning::Criterion>(state.range(0));
  for (auto _ : state) {
    const planning::PlanResult r = planning::PlanMeasurements(problem, start, options);
    if (!r.ok) state.SkipWithError(r.message.c_str());
  }
  state.SetLabel(planning::CriterionName(options.criterion));
}
BENCHMARK(BM_Plan25Poses)->Arg(0)->Arg(1)->Arg(2)->ArgName("criterion")->Unit(benchmark::kMillisecond);

// One evaluation of an exchange candidate (planning/fisher_design.h): the Fisher information of 15
// identification poses over 80 dots, every dot marginalised, with 14 poses summed and their dots eliminated
// once (Rest) and the 15th the candidate.
void BM_FisherExchangeEvaluation(benchmark::State& state) {
  planning::PlanningProblem problem;
  problem.robot = World().truth.nominal;
  problem.camera = World().observations.camera;
  problem.scene = planning::Scene::FromDots(World().truth.dots_in_base);
  std::vector<int> free_columns;
  for (int k = 6; k < 6 + 5 * problem.robot.num_joints() && free_columns.size() < 24; ++k) free_columns.push_back(k);
  planning::FisherDesign design(problem, free_columns, planning::FisherDesignOptions());
  std::vector<int> chosen;
  for (int i = 0; i < 15; ++i) chosen.push_back(design.AddCandidate(World().observations.poses[i].joints_rad));
  const int extra = design.AddCandidate(World().observations.poses[20].joints_rad);
  const planning::FisherDesign::Rest rest = design.PrepareRest(design.Sum(chosen, 7));
  const bool with_variances = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(design.EvaluateWithRest(rest, extra, with_variances));
}
BENCHMARK(BM_FisherExchangeEvaluation)->Arg(0)->Arg(1)->ArgName("with_variances")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace selfcal

BENCHMARK_MAIN();

// Growth of a whole calibration (calibration::Calibrate, method bundle: the paper pipeline, the kinematic
// bundle adjustment, the held-out checks and the predicted 3-D error) with the number of poses and of
// dots, on the simulated PUMA 560 in point mode (projected dots, pixel noise 0.2 px, world and noise seed
// 1). Poses: the shipped arc generator with N poses, the first 3N/5 identification and the rest
// verification (15 + 10 at N = 25). Process CPU time per calibration; docs/performance.md has the table
// and the fitted exponents (scripts/bench-exponents).
#include <map>
#include <utility>

#include <benchmark/benchmark.h>

#include "calibration/calibrate.h"
#include "sim/sim_world.h"
#include "sim/trajectory_generator.h"
#include "support/test_robots.h"

namespace selfcal {
namespace {

// The seeded world of `poses` x `dots`, built once per size outside the timed loop.
const sim::SimResult& World(int poses, int dots) {
  static std::map<std::pair<int, int>, sim::SimResult> worlds;
  auto it = worlds.find({poses, dots});
  if (it != worlds.end()) return it->second;
  const RobotModel puma = testing::Puma560();
  sim::ArcTrajectoryOptions arc;
  arc.num_poses = poses;
  sim::SimOptions options;
  options.pixel_noise_px = 0.2;
  options.num_dots = dots;
  options.num_identification_poses = 3 * poses / 5;
  return worlds[{poses, dots}] = sim::Simulate(puma, sim::MakeArcTrajectory(puma, arc).joints, options);
}

void BM_Calibrate(benchmark::State& state) {
  const sim::SimResult& world = World(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  if (!world.ok) {
    state.SkipWithError(world.message.c_str());
    return;
  }
  calibration::Verdict verdict = calibration::Verdict::kSolverFailure;
  for (auto _ : state) {
    const calibration::CalibrationReport r = calibration::Calibrate(world.observations, calibration::CalibrateOptions());
    // Every stage ran when the bundle converged; its acceptance may still refuse (a 5 % false refusal).
    if (!r.bundle || r.bundle->bundle.outcome != bundle::Outcome::kConverged) state.SkipWithError(r.message.c_str());
    verdict = r.verdict;
  }
  state.SetLabel(calibration::VerdictName(verdict));
}
// Poses at 80 dots, then dots at 25 poses.
BENCHMARK(BM_Calibrate)
    ->ArgNames({"poses", "dots"})
    ->Args({25, 80})
    ->Args({50, 80})
    ->Args({100, 80})
    ->Args({200, 80})
    ->Args({400, 80})
    ->Args({25, 400})
    ->Args({25, 2000})
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace selfcal

BENCHMARK_MAIN();

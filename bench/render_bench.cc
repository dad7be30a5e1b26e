// Image-mode simulation (sim::RenderDots, modules/sim/image_renderer.h) of one 640x480 frame of the
// simulated PUMA 560's 80 dots (the shipped arc's first pose, world seed 1, dots spaced so that none
// touch, 4 mm discs 11-14 px across, 8 x 8 supersampling, the true camera with its k1): without noise,
// with the study's img-I noise (grey sigma 2) and with img-II-blur (sigma 5, blur 1 px). CPU time per
// frame; docs/performance.md has the table.
#include <benchmark/benchmark.h>

#include <vector>

#include "sim/image_formation.h"
#include "sim/image_renderer.h"
#include "sim/sim_world.h"
#include "support/sim_worlds.h"

namespace selfcal {
namespace {

const sim::SimResult& World() {
  static const sim::SimResult world = [] {
    sim::SimOptions options;
    options.separation_dot_radius_m = sim::kDefaultDotRadiusM;
    return testing::PumaArcWorld(options);
  }();
  return world;
}

void BM_RenderFrame(benchmark::State& state) {
  const sim::SimResult& world = World();
  if (!world.ok) {
    state.SkipWithError(world.message.c_str());
    return;
  }
  const sim::DotScene scene = sim::MakeDotScene(world.truth);
  sim::RenderOptions options;
  options.noise_std_grey = static_cast<double>(state.range(0));
  options.blur_sigma_px = static_cast<double>(state.range(1));
  int visible = 0;
  for (auto _ : state) {
    const sim::RenderedImage frame =
        sim::RenderDots(world.truth.camera_true, world.truth.base_from_cam[0], scene, options, /*noise_seed=*/7);
    visible = 0;
    for (const sim::RenderedDot& dot : frame.dots) visible += dot.visible ? 1 : 0;
    benchmark::DoNotOptimize(frame.image.bitmap);
  }
  state.counters["visible_dots"] = visible;
}
BENCHMARK(BM_RenderFrame)->ArgNames({"noise_grey", "blur_px"})->Args({0, 0})->Args({2, 0})->Args({5, 1})
    ->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

// The renderer's Gaussian noise alone: one frame's 640 x 480 deviates.
void BM_GaussianNoiseFrame(benchmark::State& state) {
  std::vector<double> deviates(640 * 480);
  uint64_t seed = 7;
  for (auto _ : state) {
    sim::GaussianNoise noise(seed++);
    noise.Fill(deviates.data(), deviates.size());
    benchmark::DoNotOptimize(deviates.data());
  }
}
BENCHMARK(BM_GaussianNoiseFrame)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

}  // namespace
}  // namespace selfcal

BENCHMARK_MAIN();

// Reading an observations file (docs/performance.md): the one `selfcal simulate --points` writes with its
// defaults (the PUMA 560 of config/robots, its shipped trajectory of 25 poses, 80 dots, seed 1, about
// 114 KB), made once outside the timed loop and written to a temporary file. BM_ParseYamlText: the strict
// YAML reader alone on the text in memory (yaml::ParseYamlText: checks, parse, tree); BM_LoadObservations:
// what `selfcal calibrate FILE` does before solving (read, parse, schema, ObservationSet). Process CPU time.
#include <cstdio>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "base/atomic_file.h"
#include "io/observations_file.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"
#include "sim/sim_world.h"
#include "yaml/yaml_reader.h"

namespace selfcal {
namespace {

// The observations file of `selfcal simulate --points` (default robot, trajectory and seed); "" on failure.
const std::string& ObservationsPath() {
  static const std::string path = [] {
    const std::string source = SELFCAL_SOURCE_DIR;
    Result<RobotModel> robot = io::LoadRobotModel(source + "/config/robots/puma560.yaml");
    if (!robot.ok()) return std::string();
    Result<io::TrajectoryFile> trajectory =
        io::LoadTrajectoryFile(source + "/" + io::InitialTrajectoryPath(robot->name), *robot);
    if (!trajectory.ok()) return std::string();
    const sim::SimResult world = sim::Simulate(*robot, trajectory->poses, sim::SimOptions());
    const std::string out = (std::filesystem::temp_directory_path() / "selfcal_yaml_bench_observations.yaml").string();
    if (!world.ok || !io::SaveObservations(world.observations, out).ok()) return std::string();
    return out;
  }();
  return path;
}

void BM_ParseYamlText(benchmark::State& state) {
  Result<std::string> text = ReadFileCapped(ObservationsPath(), yaml::kMaxYamlBytes);
  if (ObservationsPath().empty() || !text.ok()) {
    state.SkipWithError("could not write the observations file");
    return;
  }
  for (auto _ : state) {
    Result<yaml::YamlDocument> doc = yaml::ParseYamlText(*text, "observations.yaml");
    if (!doc.ok()) state.SkipWithError(doc.status().message().c_str());
    benchmark::DoNotOptimize(doc);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(text->size()));
  state.SetLabel(std::to_string(text->size()) + " bytes");
}
BENCHMARK(BM_ParseYamlText)->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);

void BM_LoadObservations(benchmark::State& state) {
  if (ObservationsPath().empty()) {
    state.SkipWithError("could not write the observations file");
    return;
  }
  for (auto _ : state) {
    Result<ObservationSet> set = io::LoadObservations(ObservationsPath());
    if (!set.ok()) state.SkipWithError(set.status().message().c_str());
    benchmark::DoNotOptimize(set);
  }
}
BENCHMARK(BM_LoadObservations)->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace selfcal

BENCHMARK_MAIN();

// run.json -> the simulated cell's options: every recorded setting reaches the cell; a missing or
// mistyped key is refused naming the file and the key; only the simulated robot and camera count as a
// simulated run.
#include "simulation/sim_run_settings.h"

#include <gtest/gtest.h>

namespace selfcal::simulation {
namespace {

nlohmann::json RunJson() {
  return {{"format", "selfcal-run"}, {"version", 1}, {"robot", "sim"}, {"camera", "sim"}, {"seed", 7},
          {"grey_noise", 3.5}, {"blur_px", 0.25}, {"supersampling", 2},
          {"faults",
           {{"reject_moves", {1}}, {"protective_stop_moves", {2}}, {"hang_moves", {3}}, {"disconnect_moves", {4}},
            {"jog_after_moves", {5, 6}}, {"slow_settle_moves", {7}}, {"stale_reads", {8}}, {"nan_reads", {9}},
            {"short_reads", {10}}}}};
}

TEST(SimRunSettings, EveryRecordedSettingReachesTheCell) {
  const Result<SimCellOptions> o = SimCellOptionsFor(RunJson());
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->world.world_seed, 7u);
  EXPECT_EQ(o->world.noise_seed, 7u);
  EXPECT_EQ(o->camera.render.noise_std_grey, 3.5);
  EXPECT_EQ(o->camera.render.blur_sigma_px, 0.25);
  EXPECT_EQ(o->camera.render.supersampling, 2);
  EXPECT_EQ(o->faults.reject_moves, std::set<int>{1});
  EXPECT_EQ(o->faults.protective_stop_moves, std::set<int>{2});
  EXPECT_EQ(o->faults.hang_moves, std::set<int>{3});
  EXPECT_EQ(o->faults.disconnect_moves, std::set<int>{4});
  EXPECT_EQ(o->faults.jog_after_moves, (std::set<int>{5, 6}));
  EXPECT_EQ(o->faults.slow_settle_moves, std::set<int>{7});
  EXPECT_EQ(o->faults.stale_reads, std::set<int>{8});
  EXPECT_EQ(o->faults.nan_reads, std::set<int>{9});
  EXPECT_EQ(o->faults.short_reads, std::set<int>{10});
  EXPECT_TRUE(IsSimulatedRun(RunJson()));
}

TEST(SimRunSettings, RefusesAMissingOrMistypedKeyByName) {
  nlohmann::json missing = RunJson();
  missing.erase("blur_px");
  const Result<SimCellOptions> a = SimCellOptionsFor(missing, "s/inputs/run.json");
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(a.status().message().find("s/inputs/run.json: key \"blur_px\" is missing"), std::string::npos);
  nlohmann::json mistyped = RunJson();
  mistyped["faults"]["nan_reads"] = "often";
  const Result<SimCellOptions> b = SimCellOptionsFor(mistyped);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.status().message().find("\"nan_reads\""), std::string::npos) << b.status().message();
}

TEST(SimRunSettings, OnlyTheSimulatedRobotAndCameraAreASimulatedRun) {
  nlohmann::json run = RunJson();
  run["robot"] = "network";
  EXPECT_FALSE(IsSimulatedRun(run));
  run["robot"] = "sim";
  run["camera"] = "v4l2";
  EXPECT_FALSE(IsSimulatedRun(run));
  EXPECT_FALSE(IsSimulatedRun(nlohmann::json::array()));
}

}  // namespace
}  // namespace selfcal::simulation

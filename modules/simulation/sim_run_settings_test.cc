// run.json -> the simulated cell's options: every recorded setting reaches the cell; every refusal (text
// that is not JSON or not an object, a missing or mistyped key, a value out of range, an unknown fault
// key) names the file and the line of the key; only the simulated robot and camera count as a simulated
// run.
#include "simulation/sim_run_settings.h"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace selfcal::simulation {
namespace {

nlohmann::json RunJson() {
  return {{"format", "selfcal-run"}, {"version", 1}, {"robot", "sim"}, {"address", ""}, {"camera", "sim"},
          {"device", ""}, {"velocity_scaling", 1.0}, {"seed", 7},
          {"grey_noise", 3.5}, {"blur_px", 0.25}, {"supersampling", 2},
          {"faults",
           {{"reject_moves", {1}}, {"protective_stop_moves", {2}}, {"hang_moves", {3}}, {"disconnect_moves", {4}},
            {"jog_after_moves", {5, 6}}, {"slow_settle_moves", {7}}, {"stale_reads", {8}}, {"nan_reads", {9}},
            {"short_reads", {10}}}}};
}

// As `selfcal run` writes it.
std::string Text(const nlohmann::json& run) { return run.dump(2) + "\n"; }

// The 1-based line of the first occurrence of `needle` in `text` (0 when absent).
int LineOf(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  if (at == std::string::npos) return 0;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

// The refusal of `text` as s/inputs/run.json; expects kInvalidInput.
std::string Refusal(const std::string& text) {
  const Result<SimCellOptions> o = SimCellOptionsFor(text, "s/inputs/run.json");
  EXPECT_FALSE(o.ok());
  if (o.ok()) return "";
  EXPECT_EQ(o.status().code(), ErrorCode::kInvalidInput);
  return o.status().message();
}

// True when `message` holds "s/inputs/run.json:<line>: " followed (somewhere) by `what`.
::testing::AssertionResult NamesLine(const std::string& message, int line, const std::string& what) {
  const std::string at = "s/inputs/run.json:" + std::to_string(line) + ": ";
  const std::size_t i = message.find(at);
  if (line > 0 && i != std::string::npos && message.find(what, i) != std::string::npos) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "\"" << message << "\" lacks \"" << at << "..." << what << "\"";
}

TEST(SimRunSettings, EveryRecordedSettingReachesTheCell) {
  nlohmann::json run = RunJson();
  run["faults"]["jog_delay_s"] = 0.75;
  run["faults"]["never_settle_moves"] = {11};
  const Result<SimCellOptions> o = SimCellOptionsFor(Text(run));
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
  EXPECT_EQ(o->faults.jog_delay_s, 0.75);
  EXPECT_EQ(o->faults.never_settle_moves, std::set<int>{11});
  // Without "jog_delay_s" (the default, not written) the cell keeps the simulated robot's default.
  const Result<SimCellOptions> d = SimCellOptionsFor(Text(RunJson()));
  ASSERT_TRUE(d.ok()) << d.status().message();
  EXPECT_EQ(d->faults.jog_delay_s, robot::SimulatedRobotFaults().jog_delay_s);
  // The largest seed survives (an unsigned 64-bit integer, not a double).
  run["seed"] = 18446744073709551615u;
  const Result<SimCellOptions> big = SimCellOptionsFor(Text(run));
  ASSERT_TRUE(big.ok()) << big.status().message();
  EXPECT_EQ(big->world.world_seed, 18446744073709551615u);
}

TEST(SimRunSettings, RefusesTextThatIsNotAJsonObjectNamingTheLine) {
  const std::string broken = "{\n  \"seed\": 7,\n  \"grey_noise\": 2 3\n}\n";
  EXPECT_TRUE(NamesLine(Refusal(broken), 3, "not JSON"));
  EXPECT_TRUE(NamesLine(Refusal("\n[\n  1\n]\n"), 2, "not a JSON object (found array)"));
  EXPECT_TRUE(NamesLine(Refusal(""), 1, "not JSON"));
}

TEST(SimRunSettings, RefusesAMissingKeyAtItsObjectsLine) {
  nlohmann::json run = RunJson();
  run.erase("blur_px");
  EXPECT_TRUE(NamesLine(Refusal(Text(run)), 1, "missing key `blur_px`"));
  run = RunJson();
  run["faults"].erase("nan_reads");
  const std::string text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"faults\""), "missing key `nan_reads` in `faults`"));
}

TEST(SimRunSettings, RefusesAMistypedKeyNamingItsLine) {
  nlohmann::json run = RunJson();
  run["faults"]["nan_reads"] = "often";
  std::string text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"nan_reads\""), "`faults.nan_reads` must be an array"));
  run = RunJson();
  run["seed"] = "7";
  text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"seed\""), "`seed` must be an integer"));
  run = RunJson();
  run["faults"] = nlohmann::json::array();
  text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"faults\""), "`faults` must be an object (found array)"));
  run = RunJson();
  run["supersampling"] = 2.5;
  text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"supersampling\""), "`supersampling` must be an integer"));
  // A call count that is not one, at the line of the element itself.
  run = RunJson();
  run["faults"]["reject_moves"] = {1, "x"};
  text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"x\""), "`faults.reject_moves[1]` must be a call count"));
}

TEST(SimRunSettings, RefusesAValueOutOfTheRangeRunAcceptsNamingItsLine) {
  const std::pair<const char*, nlohmann::json> cases[] = {
      {"grey_noise", 50.5}, {"blur_px", -0.25}, {"supersampling", 9}, {"supersampling", 0}, {"seed", -1}};
  for (const auto& [key, value] : cases) {
    nlohmann::json run = RunJson();
    run[key] = value;
    const std::string text = Text(run);
    EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"" + std::string(key) + "\""), "`" + std::string(key) + "`"))
        << key << " = " << value;
  }
  nlohmann::json run = RunJson();
  run["faults"]["jog_delay_s"] = 11.0;
  std::string text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"jog_delay_s\""), "`faults.jog_delay_s` must be in [0, 10]"));
  run = RunJson();
  run["faults"]["hang_moves"] = {3, -1};
  text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "-1"), "`faults.hang_moves[1]` must be a call count"));
}

TEST(SimRunSettings, RefusesAnUnknownFaultNamingItsLine) {
  nlohmann::json run = RunJson();
  run["faults"]["crash_moves"] = {2};
  const std::string text = Text(run);
  EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"crash_moves\""), "unknown key `crash_moves` in `faults`"));
}

TEST(SimRunSettings, NamesEveryProblemOfTheFile) {
  nlohmann::json run = RunJson();
  run["grey_noise"] = "loud";
  run["faults"]["stale_reads"] = 3;
  const std::string text = Text(run);
  const std::string message = Refusal(text);
  EXPECT_TRUE(NamesLine(message, LineOf(text, "\"grey_noise\""), "`grey_noise`"));
  EXPECT_TRUE(NamesLine(message, LineOf(text, "\"stale_reads\""), "`faults.stale_reads`"));
}

TEST(SimRunSettings, OnlyTheSimulatedRobotAndCameraAreASimulatedRun) {
  nlohmann::json run = RunJson();
  Result<RunBackends> backends = ReadRunBackends(Text(run), "s/inputs/run.json");
  ASSERT_TRUE(backends.ok()) << backends.status().message();
  EXPECT_TRUE(backends->simulated());
  EXPECT_EQ(backends->robot_at, "s/inputs/run.json:" + std::to_string(LineOf(Text(run), "\"robot\"")));
  run["robot"] = "network";
  backends = ReadRunBackends(Text(run));
  ASSERT_TRUE(backends.ok());
  EXPECT_EQ(backends->robot, "network");
  EXPECT_FALSE(backends->simulated());
  run["robot"] = "ur";  // a session of the Universal Robots backend is read, and is not simulated
  backends = ReadRunBackends(Text(run));
  ASSERT_TRUE(backends.ok()) << backends.status().message();
  EXPECT_FALSE(backends->simulated());
  run["robot"] = "sim";
  run["camera"] = "v4l2";
  backends = ReadRunBackends(Text(run));
  ASSERT_TRUE(backends.ok());
  EXPECT_FALSE(backends->simulated());
}

TEST(SimRunSettings, AnAravisCameraAndItsRecordedModeAreARealRun) {
  nlohmann::json run = RunJson();
  run["robot"] = "network";
  run["camera"] = "aravis";
  run["device"] = "Basler-acA1920-40gm-12345678";
  run["camera_mode"] = {{"width_px", 1920}, {"height_px", 1200}, {"exposure_ms", 4}};
  const Result<RunBackends> backends = ReadRunBackends(Text(run));
  ASSERT_TRUE(backends.ok()) << backends.status().message();
  EXPECT_EQ(backends->camera, "aravis");
  EXPECT_FALSE(backends->simulated());
}

TEST(SimRunSettings, RefusesBackendsThatAreNotNamesNamingTheLine) {
  nlohmann::json run = RunJson();
  run["robot"] = 5;
  const std::string text = Text(run);
  const Result<RunBackends> backends = ReadRunBackends(text, "s/inputs/run.json");
  ASSERT_FALSE(backends.ok());
  EXPECT_EQ(backends.status().code(), ErrorCode::kInvalidInput);
  EXPECT_TRUE(NamesLine(backends.status().message(), LineOf(text, "\"robot\""), "`robot` must be a string"));
  const Result<RunBackends> array = ReadRunBackends("[]", "s/inputs/run.json");
  ASSERT_FALSE(array.ok());
  EXPECT_TRUE(NamesLine(array.status().message(), 1, "not a JSON object"));
}

// A reproducer kept in fuzz/regressions/run_settings/.
std::string Reproducer(const std::string& name) {
  std::ifstream in(std::string(SELFCAL_SOURCE_DIR) + "/fuzz/regressions/run_settings/" + name);
  EXPECT_TRUE(in.good()) << name;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Issue 36: a key given twice was taken, the last value winning; both readers refuse it naming the line of
// the second and the first.
TEST(SimRunSettings, RefusesAKeyGivenTwiceNamingBothLines) {
  const std::string seed = Reproducer("duplicate-key-seed.json");
  EXPECT_TRUE(NamesLine(Refusal(seed), LineOf(seed, "\"seed\": 2"), "`seed` is given twice (lines " +
                                                                       std::to_string(LineOf(seed, "\"seed\": 1")) + " and "));
  const Result<RunBackends> backends = ReadRunBackends(seed, "s/inputs/run.json");
  ASSERT_FALSE(backends.ok());
  EXPECT_TRUE(NamesLine(backends.status().message(), LineOf(seed, "\"seed\": 2"), "`seed` is given twice"));
  const std::string faults = Reproducer("duplicate-key-in-faults.json");
  EXPECT_TRUE(NamesLine(Refusal(faults), LineOf(faults, "\"nan_reads\": [3]"), "`faults.nan_reads` is given twice"));
}

// Issue 36: `selfcal audit` took these although docs/session-format.md says run.json's readers check them.
TEST(SimRunSettings, ChecksEveryKeyTheFormatDocumentsNamingTheLine) {
  const std::pair<const char*, std::pair<std::string, std::string>> cases[] = {
      {"velocity-scaling-text.json", {"\"velocity_scaling\"", "`velocity_scaling` must be a finite number (found string)"}},
      {"velocity-scaling-negative.json", {"\"velocity_scaling\"", "`velocity_scaling` must be in [0.001, 1] (found -999999"}},
      {"version-negative.json", {"\"version\"", "`version` must be 1 (found -3)"}},
      {"address-missing.json", {"{", "missing key `address`"}},
  };
  for (const auto& [file, expected] : cases) {
    const std::string text = Reproducer(file);
    const int line = LineOf(text, expected.first);
    EXPECT_TRUE(NamesLine(Refusal(text), line, expected.second)) << file;
    const Result<RunBackends> backends = ReadRunBackends(text, "s/inputs/run.json");
    ASSERT_FALSE(backends.ok()) << file;
    EXPECT_TRUE(NamesLine(backends.status().message(), line, expected.second)) << file;
  }
  const std::pair<const char*, nlohmann::json> more[] = {
      {"format", "selfcal-runs"}, {"version", "1"}, {"robot", "ur5"},     {"camera", "usb"},
      {"address", 5},             {"device", nullptr}, {"velocity_scaling", 0.0}, {"velocity_scaling", 1.5},
      {"extra", 1}};
  for (const auto& [key, value] : more) {
    nlohmann::json run = RunJson();
    run[key] = value;
    const std::string text = Text(run);
    EXPECT_TRUE(NamesLine(Refusal(text), LineOf(text, "\"" + std::string(key) + "\""), "`" + std::string(key) + "`"))
        << key << " = " << value;
  }
}

}  // namespace
}  // namespace selfcal::simulation

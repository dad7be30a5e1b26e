// `selfcal audit SESSION`: a short simulated session's identities scored against the simulator's truth
// (no wrong name; the same counts on stdout and in the JSON), and nothing in the session changed; a
// session not recorded with the simulated robot, a session whose recorded setup the rebuilt world does
// not reproduce, and a --json inside the session are refused with exit 2.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/sha256.h"
#include "support/cli.h"
#include "support/run_binary.h"
#include "support/temp_files.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;
using testing::ReadFile;
using testing::WriteShortPlan;
using testing::WriteFile;

int RunSelfcal(const std::string& arguments, std::string* output) { return testing::RunSelfcal(arguments, output); }

using testing::Contains;

// Replaces the recorded input `name` of the session copy at `session` and its size and SHA-256 in
// session.json, as if it had been recorded so.
void RewriteInput(const fs::path& session, const std::string& name, const std::string& contents) {
  const fs::path input = session / "inputs" / name;
  fs::permissions(input, fs::perms::owner_write, fs::perm_options::add);
  WriteFile(input.string(), contents);
  nlohmann::json manifest = nlohmann::json::parse(ReadFile((session / "session.json").string()));
  for (nlohmann::json& entry : manifest["inputs"]) {
    if (entry["name"] != name) continue;
    entry["bytes"] = contents.size();
    entry["sha256"] = Sha256Hex(contents);
  }
  WriteFile((session / "session.json").string(), manifest.dump(2) + "\n");
}

class AuditSessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() / ("selfcal_audit_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_);
    WriteShortPlan(*root_ / "plan.yaml", 6, 4);
    run_code_ = RunSelfcal("run --backend sim --camera sim --seed 2 --plan " + (*root_ / "plan.yaml").string() +
                               " --session " + (*root_ / "s").string(),
                           &run_output_);
  }
  // Every test fails (not skips) when the session could not be recorded.
  void SetUp() override { ASSERT_EQ(run_code_, 0) << run_output_; }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  // A copy of the recorded session to change.
  static fs::path Copy(const std::string& name) {
    const fs::path copy = *root_ / name;
    fs::copy(*root_ / "s", copy, fs::copy_options::recursive);
    return copy;
  }
  // The audit of a copy of the session whose recorded JSON input `name` was changed by `change`.
  static int AuditChanged(const std::string& copy_name, const std::string& name,
                          const std::function<void(nlohmann::json*)>& change, std::string* output) {
    const fs::path session = Copy(copy_name);
    nlohmann::json input = nlohmann::json::parse(ReadFile((session / "inputs" / name).string()));
    change(&input);
    RewriteInput(session, name, input.dump(2) + "\n");
    return RunSelfcal("audit " + session.string(), output);
  }
  // The 1-based line of the first `needle` in `file`, as text (the line a refusal names).
  static std::string LineOf(const fs::path& file, const std::string& needle) {
    const std::string text = ReadFile(file.string());
    const std::size_t at = text.find(needle);
    EXPECT_NE(at, std::string::npos) << needle;
    const auto end = text.begin() + static_cast<long>(std::min(at, text.size()));
    return std::to_string(1 + std::count(text.begin(), end, '\n'));
  }
  static fs::path* root_;
  static int run_code_;
  static std::string run_output_;
};
fs::path* AuditSessionTest::root_ = nullptr;
int AuditSessionTest::run_code_ = -1;
std::string AuditSessionTest::run_output_;

TEST_F(AuditSessionTest, ScoresEveryNameRightAndChangesNothing) {
  const fs::path session = *root_ / "s";
  const std::string journal = ReadFile((session / "journal.log").string());
  std::string output;
  const fs::path json = *root_ / "audit.json";
  ASSERT_EQ(RunSelfcal("audit " + session.string() + " --json " + json.string(), &output), 0) << output;
  const nlohmann::json audit = nlohmann::json::parse(ReadFile(json.string()));
  const nlohmann::json& ids = audit["identities"];
  EXPECT_EQ(ids["poses_planned"], 6);
  EXPECT_EQ(ids["samples_accepted"], 6) << output;
  EXPECT_EQ(ids["wrong_total"], 0) << output;
  EXPECT_TRUE(ids["worst_wrong"].is_null());
  // Right names lie within the centroid noise and disc-centre bias of their true projection, far inside the gate.
  EXPECT_LT(ids["max_right_error_px"].get<double>(), 0.5) << output;
  EXPECT_GT(ids["in_view_per_sample"]["min"].get<int>(), 0);
  EXPECT_TRUE(Contains(output, "6/6 samples accepted")) << output;
  EXPECT_TRUE(Contains(output, " 0 wrong identities")) << output;
  EXPECT_EQ(ReadFile((session / "journal.log").string()), journal);
}

TEST_F(AuditSessionTest, RefusesASessionNotRecordedWithTheSimulatedRobot) {
  std::string output;
  EXPECT_EQ(AuditChanged("manual", "run.json",
                         [](nlohmann::json* run) {
                           (*run)["robot"] = "manual";
                           (*run)["camera"] = "v4l2";
                         },
                         &output),
            2)
      << output;
  EXPECT_TRUE(Contains(output, "recorded with robot \"manual\"")) << output;
  EXPECT_TRUE(Contains(output, "simulated camera")) << output;
  const std::string line = LineOf(*root_ / "manual" / "inputs" / "run.json", "\"robot\"");
  EXPECT_TRUE(Contains(output, "inputs/run.json:" + line + "): only a session recorded")) << output;
}

TEST_F(AuditSessionTest, RefusesARunJsonValueOutOfRangeNamingItsLine) {
  std::string output;
  EXPECT_EQ(AuditChanged("bad_run", "run.json", [](nlohmann::json* run) { (*run)["supersampling"] = 9; }, &output), 2)
      << output;
  const fs::path run_json = *root_ / "bad_run" / "inputs" / "run.json";
  const std::string line = LineOf(run_json, "\"supersampling\"");
  EXPECT_TRUE(Contains(output, run_json.string() + ":" + line + ": `supersampling` must be in [1, 8] (found 9)"))
      << output;
}

TEST_F(AuditSessionTest, RefusesASessionWhoseSetupTheRebuiltWorldDoesNotReproduce) {
  std::string output;
  EXPECT_EQ(AuditChanged("other_setup", "setup.json", [](nlohmann::json* setup) { (*setup)["pixel_noise_px"] = 0.5; },
                         &output),
            2)
      << output;
  const fs::path setup_json = *root_ / "other_setup" / "inputs" / "setup.json";
  const std::string line = LineOf(setup_json, "\"pixel_noise_px\"");
  EXPECT_TRUE(Contains(output, setup_json.string() + ":" + line + ": `pixel_noise_px` is 0.5 where the simulated world"))
      << output;
  EXPECT_TRUE(Contains(output, "does not reproduce")) << output;
}

// A key of the recorded setup the rebuilt world does not have, and a key given twice: named by line.
TEST_F(AuditSessionTest, RefusesAnUnknownOrRepeatedSetupKeyNamingItsLine) {
  std::string output;
  EXPECT_EQ(AuditChanged("extra_setup", "setup.json", [](nlohmann::json* setup) { (*setup)["camera"]["k9"] = 1; },
                         &output),
            2)
      << output;
  const fs::path extra = *root_ / "extra_setup" / "inputs" / "setup.json";
  EXPECT_TRUE(Contains(output, extra.string() + ":" + LineOf(extra, "\"k9\"") + ": ")) << output;
  EXPECT_TRUE(Contains(output, "k9")) << output;

  const fs::path session = Copy("twice_setup");
  std::string text = ReadFile((session / "inputs" / "setup.json").string());
  text.replace(text.find("\"pixel_noise_px\""), 0, "\"pixel_noise_px\": 0.5,\n  ");
  RewriteInput(session, "setup.json", text);
  EXPECT_EQ(RunSelfcal("audit " + session.string(), &output), 2) << output;
  EXPECT_TRUE(Contains(output, (session / "inputs" / "setup.json").string() + ":")) << output;
  EXPECT_TRUE(Contains(output, "`pixel_noise_px` is given twice")) << output;
}

// The same setup data written otherwise (indentation, key order) is the same setup: audited, exit 0.
TEST_F(AuditSessionTest, AuditsASetupOfTheSameDataWrittenOtherwise) {
  const fs::path session = Copy("reformatted_setup");
  const nlohmann::json setup = nlohmann::json::parse(ReadFile((session / "inputs" / "setup.json").string()));
  RewriteInput(session, "setup.json", setup.dump(4) + "\n");
  std::string output;
  EXPECT_EQ(RunSelfcal("audit " + session.string(), &output), 0) << output;
}

TEST_F(AuditSessionTest, RefusesToWriteItsJsonIntoTheSession) {
  const fs::path session = *root_ / "s";
  std::string output;
  EXPECT_EQ(RunSelfcal("audit " + session.string() + " --json " + (session / "audit.json").string(), &output), 2)
      << output;
  EXPECT_FALSE(fs::exists(session / "audit.json"));
}

}  // namespace
}  // namespace selfcal

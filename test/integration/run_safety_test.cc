// `selfcal run` from the command line, as a careless user meets it (issue 36): a dry run of a resume
// changes nothing in the session it looks at (every file's SHA-256 before and after), an arm that does
// not settle halts the run (exit 4) and nothing moves after it, a resume with another plan names the first
// pose that differs on stderr, and the options that cannot apply are refused before anything happens.
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/sha256.h"
#include "io/trajectory_file.h"
#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;

int RunSelfcal(const std::string& arguments, std::string* output) { return testing::RunSelfcalInSource(arguments, output); }

// What `selfcal arguments` wrote on stderr alone (stdout dropped).
std::string StderrOf(const std::string& arguments) {
  std::string output;
  testing::RunSelfcalInSource(arguments + " 2>&1 1>/dev/null | cat", &output);
  return output;
}

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Every file and directory under `root` by its path relative to it: the SHA-256 of a file's bytes, "dir"
// for a directory.
std::map<std::string, std::string> Fingerprint(const fs::path& root) {
  std::map<std::string, std::string> prints;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(root)) {
    const std::string name = fs::relative(entry.path(), root).string();
    prints[name] = entry.is_directory() ? "dir" : Sha256Hex(testing::ReadFile(entry.path().string()));
  }
  return prints;
}

// A session of the first 6 poses of the shipped arc (4 identifying), halted by a protective stop at its
// fourth move: 3 samples accepted, resumable. *options: the options every later command on it repeats
// (a resume compares its run settings, faults included, with the recorded ones).
fs::path HaltedSession(const fs::path& dir, std::string* options) {
  const std::string plan = (dir / "plan.yaml").string();
  testing::WriteShortPlan(plan, 6, 4);
  const fs::path session = dir / "s";
  *options = " --session " + session.string() + " --seed 3 --plan " + plan + " --fault-protective-stop-move 3";
  std::string output;
  EXPECT_EQ(RunSelfcal("run" + *options, &output), 4) << output;
  return session;
}

TEST(RunSafety, ADryRunOfAResumeLeavesATornAndOrphanedSessionByteIdentical) {
  const fs::path dir = testing::FreshDir("runsafety", "dry_torn");
  std::string options;
  const fs::path session = HaltedSession(dir, &options);
  std::ofstream(session / "journal.log", std::ios::app) << "J1 000000ff 1234abcd {\"type\":\"sam";  // torn
  fs::copy_file(session / "images" / "p00_0.png", session / "images" / "stray.png");  // an orphan
  const std::map<std::string, std::string> before = Fingerprint(session);
  std::string output;
  EXPECT_EQ(RunSelfcal("run --resume --dry-run" + options, &output), 0) << output;
  EXPECT_EQ(Fingerprint(session), before) << output;
  EXPECT_FALSE(fs::exists(session / "orphans"));
  // What a real resume would repair, said on stdout.
  EXPECT_TRUE(Has(output, "torn tail")) << output;
  EXPECT_TRUE(Has(output, "would be truncated on resume")) << output;
  EXPECT_TRUE(Has(output, "stray.png is named by no journal record: it would be moved to orphans/")) << output;
  EXPECT_TRUE(Has(output, "dry run: nothing moved")) << output;
  // The real resume then does the repairs and records the rest.
  ASSERT_EQ(RunSelfcal("run --resume" + options, &output), 0) << output;
  EXPECT_TRUE(Has(output, "moved an unrecorded image aside: orphans/stray.png")) << output;
}

TEST(RunSafety, AResumeOnAReplacedJournalIsRefusedAndLeavesEveryFileAsItWas) {
  const fs::path dir = testing::FreshDir("runsafety", "dry_unreadable");
  std::string options;
  const fs::path session = HaltedSession(dir, &options);
  std::ofstream(session / "journal.log", std::ios::trunc) << "this is not a journal\n\x01\x02\x03 nor this";
  const std::map<std::string, std::string> before = Fingerprint(session);
  // Text in place of the journal is damage, not a torn tail: the dry run and the real resume both refuse it,
  // and neither cuts the journal nor moves an image (a real resume once cut it to 0 bytes and moved all 25).
  for (const std::string& resume : {std::string("run --resume --dry-run"), std::string("run --resume")}) {
    std::string output;
    EXPECT_EQ(RunSelfcal(resume + options, &output), 2) << resume << "\n" << output;
    EXPECT_EQ(Fingerprint(session), before) << resume << "\n" << output;
    EXPECT_TRUE(Has(output, "the journal is damaged or replaced")) << output;
  }
}

TEST(RunSafety, AnArmThatDoesNotSettleHaltsTheRunWithTheHardwareExitAndNoFurtherMove) {
  const fs::path dir = testing::FreshDir("runsafety", "unsettled");
  const std::string plan = (dir / "plan.yaml").string();
  testing::WriteShortPlan(plan, 6, 4);
  const fs::path session = dir / "s";
  std::string output;
  EXPECT_EQ(RunSelfcal("run --session " + session.string() + " --seed 3 --plan " + plan +
                           " --fault-never-settle-move 2",
                       &output),
            4)
      << output;
  EXPECT_TRUE(Has(output, "not_settled")) << output;
  EXPECT_TRUE(Has(output, "HALTED. The robot was told to stop.")) << output;
  EXPECT_FALSE(Has(output, "session complete")) << output;
  // The journal: a halted record at pose 2, and no move started after it.
  std::ifstream journal(session / "journal.log");
  bool halted = false;
  int moves_after = 0;
  for (std::string line; std::getline(journal, line);) {
    const nlohmann::json record = nlohmann::json::parse(line.substr(line.find('{')));
    if (record["type"] == "halted") {
      EXPECT_EQ(record["reason"], "not_settled");
      EXPECT_EQ(record["pose"], 2);
      halted = true;
    } else if (record["type"] == "move_started" && halted) {
      ++moves_after;
    }
  }
  EXPECT_TRUE(halted) << output;
  EXPECT_EQ(moves_after, 0);
}

TEST(RunSafety, AResumeWithAnotherPlanNamesTheFirstDifferingPoseOnStderr) {
  const fs::path dir = testing::FreshDir("runsafety", "other_plan");
  std::string options;
  HaltedSession(dir, &options);
  Result<io::TrajectoryFile> other = io::LoadTrajectoryFile((dir / "plan.yaml").string(), 6);
  ASSERT_TRUE(other.ok()) << other.status().message();
  other.value().poses[4][1] += 0.01;  // 0.573 deg on joint 2 of pose 4
  const std::string other_plan = (dir / "other.yaml").string();
  ASSERT_TRUE(io::SaveTrajectoryFile(*other, other_plan).ok());
  std::string with_other_plan = options;
  const std::string plan = (dir / "plan.yaml").string();
  with_other_plan.replace(with_other_plan.find(plan), plan.size(), other_plan);
  const std::string command = "run --resume --force-resume-with-changed-config" + with_other_plan;
  std::string output;
  EXPECT_EQ(RunSelfcal(command, &output), 2) << output;
  const std::string stderr_text = StderrOf(command);
  EXPECT_TRUE(Has(stderr_text, "recorded another plan than the one given")) << stderr_text;
  EXPECT_TRUE(Has(stderr_text, "pose 4 (p04)")) << stderr_text;
  EXPECT_TRUE(Has(stderr_text, "recorded [")) << stderr_text;
  EXPECT_TRUE(Has(stderr_text, "] deg, given [")) << stderr_text;
}

TEST(RunSafety, OptionsThatCannotApplyAreRefusedBeforeAnythingHappens) {
  const fs::path dir = testing::FreshDir("runsafety", "options");
  const fs::path session = dir / "s";
  testing::WriteFile((dir / "setup.json").string(), "{}");
  std::string output;
  EXPECT_EQ(RunSelfcal("run --session " + session.string() + " --setup " + (dir / "setup.json").string(), &output), 2)
      << output;
  EXPECT_TRUE(Has(StderrOf("run --session " + session.string() + " --setup " + (dir / "setup.json").string()),
                  "does not apply to --camera sim"));
  EXPECT_FALSE(fs::exists(session));
  for (const char* bad : {"nan", "inf", "0", "-0.5", "1.5", "abc"}) {
    const std::string command = "run --session " + session.string() + " --velocity-scaling " + bad;
    EXPECT_EQ(RunSelfcal(command, &output), 2) << bad << ": " << output;
    EXPECT_TRUE(Has(StderrOf(command), "--velocity-scaling")) << bad;
    EXPECT_FALSE(fs::exists(session)) << bad;
  }
}

}  // namespace
}  // namespace selfcal

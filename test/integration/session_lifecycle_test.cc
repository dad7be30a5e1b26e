// The life of a session directory from the command line (issue 12, items 4 and 6): nothing is created
// before the run can start (a dry run, a preflight refusal and a bad --address leave no directory, and
// the corrected run then succeeds), an interrupted creation is completed by --resume or removed by
// `selfcal session discard`, and a resume revisits skipped poses within --revisit-skipped.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/trajectory_file.h"

#include "support/cli.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;

int RunSelfcal(const std::string& arguments, std::string* output) { return testing::RunSelfcalInSource(arguments, output); }

fs::path FreshDir(const std::string& name) { return testing::FreshDir("life", name); }

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(SessionLifecycle, PreflightRefusalLeavesNothingAndTheCorrectedRunSucceeds) {
  const fs::path dir = FreshDir("preflight");
  // The shipped arc with its last pose's wrist turned by 1.7 rad: the move to it exceeds the 90 deg bound.
  Result<io::TrajectoryFile> plan =
      io::LoadTrajectoryFile(std::string(SELFCAL_SOURCE_DIR) + "/config/trajectories/initial_puma560.yaml", 6);
  ASSERT_TRUE(plan.ok()) << plan.status().message();
  plan.value().poses.back()[5] += 1.7;
  const std::string bad_plan = (dir / "plan.yaml").string();
  ASSERT_TRUE(io::SaveTrajectoryFile(*plan, bad_plan).ok());
  const std::string session = (dir / "s").string();
  std::string output;
  // The one plan check refuses it, with the exit code of `selfcal plan --check` (a plan with problems: 3).
  EXPECT_EQ(RunSelfcal("run --session " + session + " --seed 3 --plan " + bad_plan, &output), 3) << output;
  EXPECT_TRUE(Has(output, "preflight refused")) << output;
  EXPECT_FALSE(fs::exists(session)) << output;
  ASSERT_EQ(RunSelfcal("run --session " + session + " --seed 3", &output), 0) << output;
  EXPECT_TRUE(fs::exists(fs::path(session) / "session.json"));
}

TEST(SessionLifecycle, BadAddressLeavesNothingAndIsRefusedFirst) {
  const fs::path dir = FreshDir("address");
  const std::string session = (dir / "s").string();
  std::string output;
  // A setup for the real-camera path: the one a simulated run records.
  ASSERT_EQ(RunSelfcal("run --session " + (dir / "sim").string() + " --seed 3", &output), 0) << output;
  const std::string setup = (dir / "sim" / "inputs" / "setup.json").string();
  for (const std::string address : {"nohostport", "localhost:abc", "127.0.0.1:abc", "localhost:70000"}) {
    EXPECT_EQ(RunSelfcal("run --session " + session + " --backend network --camera v4l2 --setup " + setup +
                             " --address " + address,
                         &output),
              2)
        << output;
    EXPECT_TRUE(Has(output, "--address must be HOST:PORT")) << output;
    EXPECT_FALSE(fs::exists(session)) << address;
  }
  // A robot that does not answer: nothing sent, nothing created, and the message says so.
  EXPECT_EQ(RunSelfcal("run --session " + session + " --backend network --camera v4l2 --setup " + setup +
                           " --address 127.0.0.1:1",
                       &output),
            4)
      << output;
  EXPECT_TRUE(Has(output, "nothing was sent to the arm")) << output;
  EXPECT_FALSE(Has(output, "told to stop")) << output;
  EXPECT_FALSE(fs::exists(session));
}

// What a kill inside the session's creation leaves: the directory, its lock, an input copied and the
// temporary file of the next one, no session.json.
void MakeInterruptedCreation(const fs::path& session, const fs::path& inputs_from) {
  fs::create_directories(session / "inputs");
  std::ofstream(session / "lock").put('\n');
  fs::copy_file(inputs_from / "inputs" / "robot.yaml", session / "inputs" / "robot.yaml");
  fs::copy_file(inputs_from / "inputs" / "plan.yaml", session / "inputs" / ".plan.yaml.tmp.Ab12Cd");
}

TEST(SessionLifecycle, InterruptedCreationIsCompletedByResumeOrRemovedByDiscard) {
  const fs::path dir = FreshDir("interrupted");
  std::string output;
  ASSERT_EQ(RunSelfcal("run --session " + (dir / "clean").string() + " --seed 3", &output), 0) << output;
  const fs::path cut = dir / "cut";
  MakeInterruptedCreation(cut, dir / "clean");
  EXPECT_EQ(RunSelfcal("calibrate " + cut.string() + " --out " + (dir / "cal").string(), &output), 2) << output;
  EXPECT_TRUE(Has(output, "creation was interrupted")) << output;
  EXPECT_TRUE(Has(output, "selfcal session discard")) << output;
  EXPECT_EQ(RunSelfcal("run --session " + cut.string() + " --seed 3", &output), 2) << output;
  EXPECT_TRUE(Has(output, "holds no recorded sample")) << output;
  // Another robot config than the one the creation had copied: refused, nothing changed.
  EXPECT_EQ(RunSelfcal("run --resume --session " + cut.string() + " --seed 3 --robot-config config/robots/ur5e.yaml "
                       "--plan config/trajectories/initial_ur5e.yaml",
                       &output),
            2)
      << output;
  EXPECT_TRUE(Has(output, "interrupted with other inputs")) << output;
  EXPECT_TRUE(fs::exists(cut / "inputs" / ".plan.yaml.tmp.Ab12Cd"));
  // The same inputs: --resume creates it afresh and records the whole session.
  ASSERT_EQ(RunSelfcal("run --resume --session " + cut.string() + " --seed 3", &output), 0) << output;
  EXPECT_TRUE(Has(output, "25 samples accepted")) << output;
  EXPECT_FALSE(fs::exists(cut / "inputs" / ".plan.yaml.tmp.Ab12Cd"));
  // A recorded session is never discarded; an interrupted creation is.
  EXPECT_EQ(RunSelfcal("session discard " + cut.string(), &output), 2) << output;
  EXPECT_TRUE(Has(output, "recorded data")) << output;
  EXPECT_TRUE(fs::exists(cut / "session.json"));
  const fs::path cut2 = dir / "cut2";
  MakeInterruptedCreation(cut2, dir / "clean");
  ASSERT_EQ(RunSelfcal("session discard " + cut2.string(), &output), 0) << output;
  EXPECT_FALSE(fs::exists(cut2));
}

// Issue 16 item 5: what a SIGKILL inside the creation leaves (the lock still naming the dead process, the
// temporary file of robot.yaml, no session.json): calibrate names the interrupted creation, a resume names
// the flag that takes the stale lock over and completes the creation once the operator gives it.
TEST(SessionLifecycle, KilledCreationWithAStaleLockIsCompletedOnlyWhenTheOperatorConfirms) {
  const fs::path dir = FreshDir("stale");
  std::string output;
  ASSERT_EQ(RunSelfcal("run --session " + (dir / "clean").string() + " --seed 3", &output), 0) << output;
  const fs::path cut = dir / "cut";
  fs::create_directories(cut / "inputs");
  std::ofstream(cut / "lock") << "4242 deadhost 2026-01-01T00:00:00Z\n";
  fs::copy_file(dir / "clean" / "inputs" / "robot.yaml", cut / "inputs" / ".robot.yaml.tmp.Xy12Zw");
  EXPECT_EQ(RunSelfcal("calibrate " + cut.string() + " --out " + (dir / "cal").string(), &output), 2) << output;
  EXPECT_TRUE(Has(output, "creation was interrupted")) << output;
  EXPECT_FALSE(Has(output, "is not a regular file")) << output;
  EXPECT_FALSE(fs::exists(dir / "cal"));
  EXPECT_EQ(RunSelfcal("run --resume --session " + cut.string() + " --seed 3", &output), 2) << output;
  EXPECT_TRUE(Has(output, "its lock was left by pid 4242 on host deadhost")) << output;
  EXPECT_TRUE(Has(output, "--take-over-stale-lock")) << output;
  EXPECT_FALSE(fs::exists(cut / "session.json"));
  EXPECT_TRUE(fs::exists(cut / "inputs" / ".robot.yaml.tmp.Xy12Zw"));
  ASSERT_EQ(RunSelfcal("run --resume --take-over-stale-lock --session " + cut.string() + " --seed 3", &output), 0)
      << output;
  EXPECT_TRUE(Has(output, "25 samples accepted")) << output;
  EXPECT_TRUE(fs::exists(cut / "session.json"));
}

// Issue 16 item 1 (g): the network address is a transport detail, not a recorded input: a resume after the
// controller restarted on another port is not refused as "interrupted with other inputs" (it goes on to
// connect; nothing listens on port 1 here, so it halts before any command: exit 4, nothing sent).
TEST(SessionLifecycle, ANetworkResumeOnAnotherPortIsNotAChangedInput) {
  const fs::path dir = FreshDir("port");
  std::string output;
  ASSERT_EQ(RunSelfcal("run --session " + (dir / "clean").string() + " --seed 3", &output), 0) << output;
  const fs::path cut = dir / "cut";
  fs::create_directories(cut / "inputs");
  std::ofstream(cut / "lock").put('\n');
  for (const char* input : {"robot.yaml", "plan.yaml"}) {
    fs::copy_file(dir / "clean" / "inputs" / input, cut / "inputs" / input);
  }
  // The run.json a network run with a v4l2 camera records, whatever its --address was.
  std::ifstream in(dir / "clean" / "inputs" / "run.json");
  nlohmann::json run = nlohmann::json::parse(in);
  run["robot"] = "network";
  run["camera"] = "v4l2";
  run["device"] = "/dev/video0";
  run["velocity_scaling"] = 0.1;
  std::ofstream(cut / "inputs" / "run.json") << run.dump(2) << "\n";
  const std::string command = "run --resume --session " + cut.string() + " --backend network --camera v4l2 --setup " +
                              (dir / "clean" / "inputs" / "setup.json").string() + " --seed 3 --address 127.0.0.1:1";
  EXPECT_EQ(RunSelfcal(command, &output), 4) << output;
  EXPECT_FALSE(Has(output, "other inputs")) << output;
  EXPECT_TRUE(Has(output, "nothing was sent to the arm")) << output;
}

}  // namespace
}  // namespace selfcal

// `selfcal run --backend fanuc` against the selfcal-fanuc-fake binary on loopback (docs/fanuc.md), as a user
// meets it, with the simulated camera following the joints the fake reports: a dry run shows the
// controller's identity and sends no instruction; the whole default plan (25 poses) is recorded and
// `calibrate` accepts it; each state a person must clear (servos off, the teach pendant enabled) refuses the
// run at connect with the hardware exit code and nothing sent; each fault during a move (the connection
// dropped, the servos off, a move that never finishes, a wrong answer) halts the run with the hardware exit
// code, FRC_Abort sent, and no instruction after the fault. Bad --address values are usage errors.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli.h"
#include "support/loopback_fake.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The default plan's (config/trajectories/initial_puma560.yaml) first pose, where the fake's arm starts.
const char* kFirstPoseDeg = "33.1545,19.3429,-188.822,75.3602,43.4552,-25.34";

// selfcal-fanuc-fake with `extra` options; its address (127.0.0.1:PORT), its stdout kept in `log`.
class FanucFake {
 public:
  FanucFake(const std::vector<std::string>& extra, const fs::path& log)
      : process_(Args(extra), log, [this](const std::string& printed) {
          int port = 0;
          if (std::sscanf(printed.c_str(), "listening on 127.0.0.1:%d", &port) == 1) {
            address_ = "127.0.0.1:" + std::to_string(port);
          }
          return !address_.empty();
        }) {}
  // Stops the fake; returns everything it printed.
  std::string Stop() { return process_.Stop(); }
  const std::string& address() const { return address_; }

 private:
  static std::vector<std::string> Args(const std::vector<std::string>& extra) {
    std::vector<std::string> args = {SELFCAL_FANUC_FAKE, "--start-deg", kFirstPoseDeg};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  std::string address_;  // before process_: set while process_ is constructed
  testing::LoopbackFake process_;
};

// `run --backend fanuc --camera sim` at full speed; the operator types the serial (the address) to arm.
int FanucRun(const fs::path& dir, const std::string& address, const std::string& tail, std::string* output) {
  std::ofstream(dir / "answer") << address << "\n";
  return testing::RunSelfcalInSource("run --session " + (dir / "s").string() + " --backend fanuc --address " + address +
                                         " --camera sim --velocity-scaling 1 --live-view off " + tail + " < " +
                                         (dir / "answer").string() + " 2>&1",
                                     output);
}

TEST(FanucFakeBinary, ADryRunShowsTheControllerAndSendsNothing) {
  const fs::path dir = testing::FreshDir("fanucfake", "dry");
  FanucFake fake({}, dir / "fake.log");
  ASSERT_FALSE(fake.address().empty()) << "selfcal-fanuc-fake did not print its port";
  std::string output;
  EXPECT_EQ(FanucRun(dir, fake.address(), "--dry-run", &output), 0) << output;
  EXPECT_TRUE(Has(output, "robot fanuc FANUC RMI 1.0 serial " + fake.address() + " (REAL HARDWARE)")) << output;
  EXPECT_TRUE(Has(output, "dry run: nothing moved")) << output;
  EXPECT_FALSE(fs::exists(dir / "s"));
  const std::string log = fake.Stop();
  EXPECT_TRUE(Has(log, "motion commands 0, stop commands 0")) << log;
  EXPECT_FALSE(Has(log, "FRC_JointMotionJRep")) << log;
  EXPECT_FALSE(Has(log, "FRC_Initialize")) << log;  // nothing that could move: not even RMI started
}

TEST(FanucFakeBinary, TheWholeDefaultPlanIsRecordedAndCalibrateAcceptsIt) {
  const fs::path dir = testing::FreshDir("fanucfake", "whole");
  FanucFake fake({}, dir / "fake.log");
  ASSERT_FALSE(fake.address().empty());
  std::string output;
  ASSERT_EQ(FanucRun(dir, fake.address(), "", &output), 0) << output;
  EXPECT_TRUE(Has(output, "run: completed: session complete: 25 samples accepted")) << output;
  const std::string log = fake.Stop();
  EXPECT_TRUE(Has(log, "motion commands 25, stop commands 0")) << log;
  const std::string journal = testing::ReadFile((dir / "s" / "journal.log").string());
  EXPECT_TRUE(Has(journal, "\"robot_backend\":\"fanuc\"")) << journal.substr(0, 800);
  EXPECT_TRUE(Has(journal, "\"robot_model\":\"FANUC RMI 1.0\"")) << journal.substr(0, 800);
  EXPECT_TRUE(Has(journal, "\"robot_serial\":\"" + fake.address() + "\"")) << journal.substr(0, 800);
  EXPECT_EQ(testing::RunSelfcalInSource("calibrate " + (dir / "s").string() + " --out " + (dir / "out").string() +
                                            " --no-html 2>&1",
                                        &output),
            0)
      << output;
  EXPECT_TRUE(Has(output, "session: 25 of 25 poses accepted")) << output;
  EXPECT_TRUE(Has(output, "\naccepted: held-out")) << output;
}

TEST(FanucFakeBinary, WhatAPersonMustClearRefusesTheRunAtConnect) {
  const fs::path dir = testing::FreshDir("fanucfake", "refusals");
  struct Case {
    const char* fault;
    const char* says;
  };
  for (const Case& c : {Case{"--servo-off-at-start", "the servos are not ready"},
                        Case{"--teach-pendant-enabled", "the teach pendant is enabled"}}) {
    FanucFake fake({c.fault}, dir / (std::string(c.fault).substr(2) + ".log"));
    ASSERT_FALSE(fake.address().empty());
    std::string output;
    EXPECT_EQ(FanucRun(dir, fake.address(), "", &output), 4) << c.fault << "\n" << output;
    EXPECT_TRUE(Has(output, c.says)) << output;
    EXPECT_TRUE(Has(output, "a person must clear it at the teach pendant")) << output;
    EXPECT_TRUE(Has(output, "HALTED before any motion command: nothing was sent to the arm")) << output;
    EXPECT_FALSE(fs::exists(dir / "s")) << c.fault;
    const std::string log = fake.Stop();
    EXPECT_TRUE(Has(log, "motion commands 0, stop commands 0")) << c.fault << "\n" << log;
  }
}

TEST(FanucFakeBinary, EachFaultDuringAMoveHaltsTheRunAndNoInstructionFollows) {
  struct Case {
    const char* fault;
    const char* says;
  };
  // Move 2 (the third): the first two are recorded, the fault comes half way through the third.
  for (const Case& c : {Case{"--drop-move", "robot_disconnected"}, Case{"--servo-off-move", "the servos are not ready"},
                        Case{"--stall-move", "move_timeout"}, Case{"--wrong-answer-move", "FRC_ReadCartesianPosition"}}) {
    const fs::path dir = testing::FreshDir("fanucfake", std::string(c.fault).substr(2));
    FanucFake fake({c.fault, "2"}, dir / "fake.log");
    ASSERT_FALSE(fake.address().empty());
    std::string output;
    EXPECT_EQ(FanucRun(dir, fake.address(), "", &output), 4) << c.fault << "\n" << output;
    EXPECT_TRUE(Has(output, c.says)) << c.fault << "\n" << output;
    const std::string log = fake.Stop();
    EXPECT_TRUE(Has(log, "motion commands 3, stop commands 1")) << c.fault << "\n" << log;
    const std::string journal = testing::ReadFile((dir / "s" / "journal.log").string());
    EXPECT_TRUE(Has(journal, "\"type\":\"halted\"")) << c.fault;
  }
}

TEST(FanucFakeBinary, BadAddressesAreUsageErrorsAndNoControllerIsAHardwareHalt) {
  const fs::path dir = testing::FreshDir("fanucfake", "address");
  std::string output;
  EXPECT_EQ(testing::RunSelfcalInSource("run --session " + (dir / "s").string() + " --backend fanuc --camera sim 2>&1", &output), 2)
      << output;
  EXPECT_TRUE(Has(output, "--backend fanuc needs --address HOST[:PORT]")) << output;
  EXPECT_EQ(FanucRun(dir, "127.0.0.1:99999", "", &output), 2) << output;
  EXPECT_TRUE(Has(output, "--backend fanuc takes the controller's HOST or HOST:PORT")) << output;
  EXPECT_EQ(FanucRun(dir, "127.0.0.1:1", "", &output), 4) << output;  // nothing listens on port 1
  EXPECT_TRUE(Has(output, "nothing was sent to the arm")) << output;
  EXPECT_FALSE(fs::exists(dir / "s"));
}

}  // namespace
}  // namespace selfcal

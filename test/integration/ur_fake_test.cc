// `selfcal run --backend ur` against the selfcal-ur-fake binary on loopback (docs/universal-robots.md), as a
// user meets it: a controller that connects is identified (model, serial, the factory calibration's
// checksums) and, without a camera here, the run halts before any motion command; each state a person must
// clear at the controller (remote control off, a protective stop, a program running) and a wrong answer to the RTDE recipe
// refuses the run at connect with the hardware exit code, a message saying what to do, no session, and no
// motion command at the fake. Bad --address values are usage errors before anything is connected.
// (The session loop's halts during a move: test/cross_module/ur_session_test.cc.)
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli.h"
#include "support/loopback_fake.h"

namespace selfcal {
namespace {

namespace fs = std::filesystem;

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// selfcal-ur-fake with `extra` options; its three ports as --ur-ports' value, its stdout kept in `log`.
class UrFake {
 public:
  explicit UrFake(const std::vector<std::string>& extra, const fs::path& log)
      : process_(Args(extra), log, [this](const std::string& printed) {
          int rtde = 0, secondary = 0, dashboard = 0;
          if (std::sscanf(printed.c_str(), "listening on 127.0.0.1 rtde %d secondary %d dashboard %d", &rtde,
                          &secondary, &dashboard) == 3) {
            ports_ = std::to_string(rtde) + "," + std::to_string(secondary) + "," + std::to_string(dashboard);
          }
          return !ports_.empty();
        }) {}
  // Stops the fake; returns everything it printed.
  std::string Stop() { return process_.Stop(); }
  const std::string& ports() const { return ports_; }

 private:
  static std::vector<std::string> Args(const std::vector<std::string>& extra) {
    std::vector<std::string> args = {SELFCAL_UR_FAKE};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  std::string ports_;  // before process_: set while process_ is constructed
  testing::LoopbackFake process_;
};

// A setup.json for the real-camera path: the one a short simulated run records.
std::string SetupFile(const fs::path& dir) {
  testing::WriteShortPlan(dir / "plan.yaml", 6, 4);
  std::string output;
  EXPECT_EQ(testing::RunSelfcalInSource("run --session " + (dir / "sim").string() + " --seed 3 --plan " +
                                            (dir / "plan.yaml").string(),
                                        &output),
            0)
      << output;
  return (dir / "sim" / "inputs" / "setup.json").string();
}

std::string UrRun(const fs::path& session, const std::string& setup, const std::string& tail) {
  return "run --session " + session.string() + " --backend ur --robot-config config/robots/ur5e.yaml --camera v4l2 "
         "--device /dev/selfcal-no-such-camera --setup " + setup + " " + tail + " 2>&1";
}

TEST(UrFakeBinary, AControllerIsIdentifiedAndNothingMovesWithoutACamera) {
  const fs::path dir = testing::FreshDir("urfake", "connect");
  const std::string setup = SetupFile(dir);
  UrFake fake({}, dir / "fake.log");
  ASSERT_FALSE(fake.ports().empty()) << "selfcal-ur-fake did not print its ports";
  for (const bool dry : {true, false}) {
    std::string output;
    // A dry run opens no camera: the preview, exit 0; a real one halts at the missing camera, exit 4.
    EXPECT_EQ(testing::RunSelfcalInSource(
                  UrRun(dir / "s", setup, "--address 127.0.0.1 --ur-ports " + fake.ports() + (dry ? " --dry-run" : "")),
                  &output),
              dry ? 0 : 4)
        << output;
    EXPECT_TRUE(Has(output, "UR5e serial 20235500001, factory calibration "
                            "ur-kinematics-00001001-00001002-00001003-00001004-00001005-00001006"))
        << output;
    // The factory DH table in a robot config's keys, to start a nominal model from.
    EXPECT_TRUE(Has(output, "  - {a_mm: 0, alpha_deg: 90, d_mm: 162.5, theta_offset_deg: 0}\n"
                            "  - {a_mm: -425, alpha_deg: 0, d_mm: 0, theta_offset_deg: 0}"))
        << output;
    EXPECT_EQ(Has(output, "opening the camera"), !dry) << output;
    if (!dry) {
      EXPECT_TRUE(Has(output, "HALTED before any motion command: nothing was sent to the arm")) << output;
    }
    EXPECT_FALSE(fs::exists(dir / "s"));
  }
  const std::string log = fake.Stop();
  EXPECT_TRUE(Has(log, "motion commands 0, stop commands 0")) << log;
  EXPECT_FALSE(Has(log, "movej")) << log;
}

TEST(UrFakeBinary, WhatAPersonMustClearRefusesTheRunAtConnectAndNothingIsSent) {
  const fs::path dir = testing::FreshDir("urfake", "refusals");
  const std::string setup = SetupFile(dir);
  struct Case {
    const char* fault;
    const char* says;
  };
  for (const Case& c : {Case{"--remote-control-off", "switch the teach pendant to Remote Control"},
                        Case{"--protective-stop-at-start", "PROTECTIVE_STOP: a person must clear it"},
                        Case{"--wrong-recipe", "NOT_FOUND"},
                        Case{"--program-running", "a program is running on the controller"}}) {
    UrFake fake({c.fault}, dir / (std::string(c.fault).substr(2) + ".log"));  // a log each
    ASSERT_FALSE(fake.ports().empty());
    std::string output;
    EXPECT_EQ(testing::RunSelfcalInSource(UrRun(dir / "s", setup, "--address 127.0.0.1 --ur-ports " + fake.ports()), &output), 4)
        << c.fault << "\n" << output;
    EXPECT_TRUE(Has(output, "connecting to the robot")) << output;
    EXPECT_TRUE(Has(output, c.says)) << output;
    EXPECT_TRUE(Has(output, "HALTED before any motion command: nothing was sent to the arm")) << output;
    EXPECT_FALSE(fs::exists(dir / "s")) << c.fault;
    const std::string log = fake.Stop();
    EXPECT_TRUE(Has(log, "motion commands 0, stop commands 0")) << c.fault << "\n" << log;
  }
}

TEST(UrFakeBinary, BadAddressesAreUsageErrorsAndNoControllerIsAHardwareHalt) {
  const fs::path dir = testing::FreshDir("urfake", "address");
  const std::string setup = SetupFile(dir);
  std::string output;
  EXPECT_EQ(testing::RunSelfcalInSource(UrRun(dir / "s", setup, ""), &output), 2) << output;
  EXPECT_TRUE(Has(output, "--backend ur needs --address HOST")) << output;
  EXPECT_EQ(testing::RunSelfcalInSource(UrRun(dir / "s", setup, "--address 127.0.0.1:30004"), &output), 2) << output;
  EXPECT_TRUE(Has(output, "takes the controller's HOST alone")) << output;
  EXPECT_EQ(testing::RunSelfcalInSource(UrRun(dir / "s", setup, "--address 127.0.0.1 --ur-ports 1,2"), &output), 2)
      << output;
  // Nothing listens on port 1: refused at connect, nothing sent, no session.
  EXPECT_EQ(testing::RunSelfcalInSource(UrRun(dir / "s", setup, "--address 127.0.0.1 --ur-ports 1,1,1"), &output), 4)
      << output;
  EXPECT_TRUE(Has(output, "nothing was sent to the arm")) << output;
  EXPECT_FALSE(fs::exists(dir / "s"));
}

}  // namespace
}  // namespace selfcal

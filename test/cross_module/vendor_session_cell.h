// The session loop (acquisition) driving a vendor backend (UR, FANUC) against its loopback fake served on a
// thread: a stub camera that opens and never gives a frame (the first pose's move needs none, and the run
// halts before its settle), a plan of four moves of 0.1 rad on joint 1 from the fake's start, a session in a
// temporary folder. Fake is the fake controller type (Serve(stop, log), motion_commands(), stop_commands()).
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "acquisition/session_runner.h"
#include "robot/clock.h"
#include "session/session_dir.h"
#include "support/temp_files.h"

namespace selfcal::testing {

class StubCamera : public capture::FrameSource {
 public:
  std::string Describe() const override { return "stub camera"; }
  Status Open() override { return Status::Ok(); }
  Result<capture::Frame> Grab(double, double) override {
    return Status::Error(ErrorCode::kHardware, "the stub camera has no frames");
  }
  void Close() override {}
};

template <typename Fake>
struct VendorCell {
  VendorCell(Fake served, const Eigen::VectorXd& start, const std::string& name)
      : fake(std::move(served)), dir(name) {
    thread = std::thread([this] { fake.Serve(stop_fake, nullptr); });
    for (int i = 0; i < 4; ++i) {
      Eigen::VectorXd q = start;
      q[0] += 0.1 * (i + 1);
      plan.push_back({"p0" + std::to_string(i), i < 3 ? PoseRole::kIdentification : PoseRole::kVerification, q});
    }
    run_options.safety.velocity_scaling = 1.0;
  }
  ~VendorCell() { StopFake(); }
  void StopFake() {
    if (stop_fake) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the last lines read
    stop_fake = true;
    thread.join();
  }
  acquisition::RunReport Run(robot::Robot* arm, bool confirm) {
    acquisition::RunContext c;
    c.robot = arm;
    c.camera = &camera;
    c.clock = &clock;
    c.identifier = &identifier;
    c.stop_requested = &stop;
    c.create_session = [this]() -> Result<session::Session*> {
      session::CreateOptions create;
      create.created_utc = "2026-12-06T00:00:00Z";
      Result<session::Session> s = session::CreateSession(dir.path() + "/s", {{"plan.json", "{}"}}, "test", create);
      if (!s.ok()) return s.status();
      created.emplace(std::move(s).value());
      return &*created;
    };
    c.confirm = [this, confirm](const std::string& text, const robot::RobotIdentity& identity) {
      preview = text;
      real_hardware = identity.real_hardware;
      return confirm;
    };
    return acquisition::RunSession(plan, c, run_options);
  }
  // A dry run (not confirmed): refused, `preview_part` in the preview, real hardware, no session, and
  // nothing at the fake (the fake stopped here).
  void ExpectDryRunSentNothing(const acquisition::RunReport& report, const std::string& preview_part) {
    EXPECT_EQ(report.outcome, acquisition::RunOutcome::kRefused) << report.message;
    EXPECT_EQ(report.message, "not confirmed: nothing was sent to the arm");
    EXPECT_NE(preview.find(preview_part), std::string::npos) << preview;
    EXPECT_TRUE(real_hardware);  // the operator types the serial before the arm moves
    EXPECT_FALSE(created.has_value());
    StopFake();
    EXPECT_EQ(fake.motion_commands(), 0);
    EXPECT_EQ(fake.stop_commands(), 0);
  }
  // A halt during the first move: the hardware error with `halt_reason`, the stop sent, one move journaled
  // and the halt last, and at the fake one motion command, none after the halt, and the stop (the fake
  // stopped here).
  void ExpectHaltAfterFirstMove(const acquisition::RunReport& report, const std::string& halt_reason,
                                const std::string& name) {
    EXPECT_EQ(report.outcome, acquisition::RunOutcome::kHalted) << name << ": " << report.message;
    EXPECT_EQ(report.error, ErrorCode::kHardware) << name;
    EXPECT_EQ(report.halt_reason, halt_reason) << name << ": " << report.message;
    EXPECT_TRUE(report.stop_sent) << name;
    ASSERT_TRUE(created.has_value()) << name;
    int moves = 0;
    for (const nlohmann::json& r : created->journal().records()) moves += r["type"] == "move_started" ? 1 : 0;
    EXPECT_EQ(moves, 1) << name;
    EXPECT_EQ(created->journal().records().back()["type"], "halted") << created->journal().records().back().dump();
    StopFake();
    EXPECT_EQ(fake.motion_commands(), 1) << name << ": only the first move, none after the halt";
    EXPECT_GE(fake.stop_commands(), 1) << name;
  }

  Fake fake;
  std::atomic<bool> stop_fake{false};
  std::thread thread;
  TempDir dir;
  StubCamera camera;
  robot::MonotonicClock clock;
  acquisition::DetectionOrderIdentifier identifier;
  std::atomic<bool> stop{false};
  std::vector<acquisition::PlannedPose> plan;
  acquisition::RunOptions run_options;
  std::optional<session::Session> created;
  std::string preview;
  bool real_hardware = false;
};

}  // namespace selfcal::testing

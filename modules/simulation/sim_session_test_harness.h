// Test support for the session loop on the simulated cell (the simulation module's tests and
// test/cross_module): a plan along the arc trajectory and a harness owning the cell, its (faulty) camera,
// a fresh session and the run options. Header-only, for tests.
#pragma once

#include <atomic>
#include <cstdio>
#include <memory>
#include <optional>

#include <gtest/gtest.h>

#include "acquisition/session_runner.h"
#include "capture/faulty_frame_source.h"
#include "session/samples.h"
#include "sim/trajectory_generator.h"
#include "simulation/sim_session.h"
#include "support/temp_files.h"
#include "support/test_robots.h"

namespace selfcal::simulation {

inline std::vector<acquisition::PlannedPose> ArcPlan(int num_poses) {
  const RobotModel puma = testing::Puma560();
  const sim::GeneratedTrajectory t = sim::MakeArcTrajectory(puma, sim::ArcTrajectoryOptions());
  EXPECT_TRUE(t.ok);
  std::vector<acquisition::PlannedPose> plan;
  for (int i = 0; i < num_poses; ++i) {
    char id[16];
    std::snprintf(id, sizeof(id), "p%02d", i);
    plan.push_back({id, i < num_poses * 3 / 5 ? PoseRole::kIdentification : PoseRole::kVerification, t.joints[i]});
  }
  return plan;
}

// A fresh session on a new simulated cell (PUMA 560, the arc plan), run with RunSession.
struct Harness {
  explicit Harness(int num_poses, SimCellOptions cell_options = SimCellOptions(),
                   capture::FrameFaults frame_faults = capture::FrameFaults())
      : plan(ArcPlan(num_poses)), dir("session_runner") {
    cell_options.camera.render.supersampling = 4;
    cell_options.camera.render.noise_std_grey = 2;
    Result<SimCell> made = MakeSimCell(testing::Puma560(), plan, cell_options, plan.front().joints_rad, 0.0);
    EXPECT_TRUE(made.ok()) << made.status().message();
    cell = std::move(made).value();
    const ObservationSet setup = SimSetup(cell);
    prediction = {testing::Puma560(), setup.camera, setup.pixel_noise_px};
    camera = std::make_unique<capture::FaultyFrameSource>(cell.camera.get(), frame_faults);
    session::CreateOptions create;
    create.created_utc = "2026-11-23T00:00:00Z";
    Result<session::Session> s = session::CreateSession(dir.path() + "/s", {{"plan.json", "{}"}}, "test", create);
    EXPECT_TRUE(s.ok()) << s.status().message();
    session.emplace(std::move(s).value());
    options.journal_sim_clock = true;
    options.safety.velocity_scaling = 1.0;
    options.settle.min_dwell_s = 0.6;
    // ArcPlan(4) has two identification poses: the harness's short sessions complete with them.
    options.min_identification_samples = 2;
  }

  acquisition::RunContext Context() {
    acquisition::RunContext c;
    c.robot = cell.robot.get();
    c.camera = camera.get();
    c.clock = cell.clock.get();
    c.session = &*session;
    c.identifier = cell.identifier.get();
    c.prediction = &prediction;
    c.stop_requested = &stop;
    c.confirm = [this](const std::string&, const robot::RobotIdentity&) { return confirm; };
    return c;
  }
  acquisition::RunReport Run() { return acquisition::RunSession(plan, Context(), options); }
  session::SessionLog Log() {
    Result<session::SessionLog> log = session::ReadSessionLog(session->journal().records());
    EXPECT_TRUE(log.ok()) << log.status().message();
    return log.ok() ? *log : session::SessionLog();
  }

  std::vector<acquisition::PlannedPose> plan;
  testing::TempDir dir;
  SimCell cell;
  acquisition::PredictionModel prediction;  // names again the dots tracking loses
  std::unique_ptr<capture::FaultyFrameSource> camera;
  std::optional<session::Session> session;
  acquisition::RunOptions options;
  std::atomic<bool> stop{false};
  bool confirm = true;
};

}  // namespace selfcal::simulation

// Sessions from the command line: `selfcal run` (robot + camera -> a session directory) and the session
// half of `selfcal simulate`. (`selfcal calibrate SESSION` reads a session through the session module.)
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/camera_options.h"
#include "app/identify_options.h"
#include "base/status.h"
#include "observations/observation_set.h"
#include "sim/sim_world.h"

namespace selfcal::app {

// The settings of `selfcal run` (and of the session half of `selfcal simulate`).
struct RunSettings {
  std::string session;
  bool resume = false;
  bool force_changed_config = false;
  bool take_over_stale_lock = false;  // the operator confirms that the process named in a stale lock is gone
  bool dry_run = false;
  int revisit_skipped = 1;  // --resume: further attempts per pose skipped for a revisitable reason
  std::string robot_config = "config/robots/puma560.yaml";
  std::string configuration = "eye_in_hand";  // --configuration (run_configuration.h)
  std::string plan;  // default: the robot's shipped trajectory (TrajectoryForRobot in cli_util.h)
  std::string setup;  // required unless --camera sim
  std::string robot_backend = "sim";
  std::string address = "127.0.0.1:5700";
  std::vector<int> ur_ports;  // --backend ur: RTDE, secondary, Dashboard ports; empty: a controller's
  std::string camera_backend = "sim";
  std::string device = "/dev/video0";
  CameraMode camera_mode;  // --camera-width-px, ..., and aravis' camera id
  double velocity_scaling = -1;  // default: 1.0 simulated, 0.1 otherwise (R1)
  uint64_t seed = 1;
  double grey_noise = 2.0;
  double blur_px = 0.0;
  int supersampling = 4;
  std::string live_view = "auto";  // --live-view auto|on|off (liveview/live_view.h)
  IdentifySettings identify;  // --identify: empty is the simulator's truth, or the detection order
  std::vector<int> fault_reject_moves, fault_pstop_moves, fault_hang_moves, fault_disconnect_moves,
      fault_jog_after_moves, fault_slow_settle_moves, fault_stale_reads, fault_nan_reads, fault_short_reads;
  std::vector<int> fault_never_settle_moves;  // recorded in run.json only when given
  double fault_jog_delay_s = 0.5;  // after the jogged move's arrival (SimulatedRobotFaults::jog_delay_s)
};

// `selfcal run` with these settings: creates or resumes the session, drives the robot, returns the exit code.
// With the simulated robot, *world (optional) receives the simulated world after the run (its hidden truth).
int RunFromSettings(RunSettings settings, std::unique_ptr<sim::SimResult>* world = nullptr);

}  // namespace selfcal::app

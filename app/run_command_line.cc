// The command line of `selfcal run` (RunSettings, session_command.h): every value checked here, before
// anything is read, connected or written.
#include <algorithm>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/camera_options.h"
#include "app/cli_util.h"
#include "app/commands.h"
#include "app/identify_options.h"
#include "app/output_options.h"
#include "app/run_configuration.h"
#include "app/session_command.h"

namespace selfcal::app {

namespace {

const std::vector<std::string> kRobotBackends = {"sim", "network", "manual", "ur", "fanuc"};

// `run --robot X`: a robot config as in every other command, or, for a backend name, --backend's old spelling
// (said on stderr). Refused when it repeats what --backend or --robot-config already says.
Status ResolveRobotWord(const std::string& word, bool backend_given, bool config_given, RunSettings* a) {
  if (word.empty()) return Status::Ok();
  const bool is_backend = std::find(kRobotBackends.begin(), kRobotBackends.end(), word) != kRobotBackends.end();
  if (is_backend && backend_given) {
    return Status::Error(ErrorCode::kInvalidInput, "--robot " + word + " and --backend " + a->robot_backend +
                                                       " both name the backend: give --backend only");
  }
  if (!is_backend && config_given) {
    return Status::Error(ErrorCode::kInvalidInput, "--robot " + word + " and --robot-config " + a->robot_config +
                                                       " both name the robot config: give one");
  }
  if (is_backend) {
    std::cerr << "note: --robot " << word << " is the old spelling of --backend " << word
              << " (--robot names the robot config, as in the other commands)\n";
    a->robot_backend = word;
  } else {
    a->robot_config = word;
  }
  return Status::Ok();
}

}  // namespace

Command AddRunCommand(CLI::App& app) {
  auto a = std::make_shared<RunSettings>();
  auto robot_word = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("run", "Drive a robot through a plan and record a session directory");
  AddOutputOption(cmd, "--session", &a->session, OutputKind::kSessionDirectory,
                  "Session directory (created, never overwritten, never inside another session)")->required();
  cmd->add_flag("--resume", a->resume, "Continue a session after a stop or crash (checks every input's hash)");
  cmd->add_flag("--force-resume-with-changed-config", a->force_changed_config,
                "Resume although an input differs from the recorded one");
  cmd->add_flag("--take-over-stale-lock", a->take_over_stale_lock,
                "--resume: take over a lock left by a process that ended without releasing it (you confirm that "
                "no selfcal on the host it names uses the session)");
  cmd->add_flag("--dry-run", a->dry_run,
                "Check the plan and print the preview; send no motion command, create or change nothing (with "
                "--resume: report what the resume would repair, and leave the session as it is)");
  cmd->add_option("--live-view", a->live_view,
                  "Show the camera image with the tracked dots, their ids and the pose in an X11 window: auto (when "
                  "$DISPLAY can be opened), on (refused without a display), off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cmd->add_option("--revisit-skipped", a->revisit_skipped,
                  "--resume: visit poses skipped for too few dots, not settled, a bad frame or reading again, at "
                  "most N more times each (0: never)")
      ->check(CLI::Range(0, 100));
  CLI::Option* config = cmd->add_option("--robot-config", a->robot_config, "Nominal robot config (the same as --robot PATH)");
  AddConfigurationOption(cmd, &a->configuration);
  cmd->add_option("--plan", a->plan, "Plan (trajectory file); default: config/trajectories/initial_<robot name>.yaml");
  cmd->add_option("--setup", a->setup,
                  "Camera, yardstick and checks (docs/session-format.md); refused with --backend sim, whose cell "
                  "makes its own");
  CLI::Option* backend = cmd->add_option("--backend", a->robot_backend, "Robot backend (default sim)")
                             ->check(CLI::IsMember(kRobotBackends));
  cmd->add_option("--robot", *robot_word,
                  "Nominal robot config, as in the other commands; a backend name here (sim, network, manual, ur, "
                  "fanuc) is --backend's old spelling, still taken with a note");
  cmd->add_option("--address", a->address,
                  "network backend: HOST:PORT (docs/robot-protocol.md); ur: the controller's HOST "
                  "(docs/universal-robots.md); fanuc: HOST[:PORT], PORT the RMI connect port (default 16001, "
                  "docs/fanuc.md)");
  cmd->add_option("--ur-ports", a->ur_ports,
                  "ur: the RTDE, secondary interface and Dashboard ports (default 30004,30002,29999; another set for "
                  "selfcal-ur-fake)")
      ->delimiter(',')
      ->expected(3)
      ->check(CLI::Range(1, 65535))
      ->default_str("");  // the default is in the text (CLI11 would show "[]")
  AddCameraOptions(cmd, &a->camera_backend, &a->camera_mode, {"sim", "v4l2", "aravis"});
  cmd->add_option("--device", a->device, "v4l2 camera device");
  cmd->add_option("--velocity-scaling", a->velocity_scaling,
                  "Fraction of the joint velocity limits (default 1 simulated, 0.1 real)")
      ->check(CLI::Range(1e-3, 1.0))  // NaN and inf: CheckNumbersStrictly (cli_numbers.h)
      ->default_str("");              // -1, the "not given" sentinel, is not a value to show
  cmd->add_option("--seed", a->seed, "sim: world, noise and robot seed");
  cmd->add_option("--grey-noise", a->grey_noise, "sim: pixel noise std, grey levels")->check(CLI::Range(0.0, 50.0));
  cmd->add_option("--blur-px", a->blur_px, "sim: Gaussian blur sigma, px")->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--supersampling", a->supersampling, "sim: samples per pixel side")->check(CLI::Range(1, 8));
  AddIdentifyOptions(cmd, &a->identify, "default: the simulator's truth with sim, else order");
  auto fault = [&](const char* name, std::vector<int>* v, const char* what) {
    cmd->add_option(name, *v, what)
        ->delimiter(',')
        ->check(CLI::NonNegativeNumber)
        ->group("Simulated faults (sim robot, 0-based call counts)");
  };
  fault("--fault-reject-move", &a->fault_reject_moves, "reject move #k");
  fault("--fault-protective-stop-move", &a->fault_pstop_moves, "protective stop half way through move #k");
  fault("--fault-hang-move", &a->fault_hang_moves, "move #k never finishes");
  fault("--fault-disconnect-move", &a->fault_disconnect_moves, "connection lost during move #k");
  fault("--fault-jog-after-move", &a->fault_jog_after_moves, "someone jogs the arm after move #k");
  cmd->add_option("--fault-jog-delay-s", a->fault_jog_delay_s,
                  "the jog comes this long after the move's arrival (0.5: while settling; the simulated session "
                  "settles 0.6 s after arrival, so a little more jogs between settle and capture)")
      ->check(CLI::Range(0.0, 10.0))
      ->group("Simulated faults (sim robot, 0-based call counts)");
  fault("--fault-slow-settle-move", &a->fault_slow_settle_moves, "move #k rings 20x longer");
  fault("--fault-never-settle-move", &a->fault_never_settle_moves,
        "after move #k every joint reads 0.05 rad/s: the arm never comes to rest (the session halts)");
  fault("--fault-stale-read", &a->fault_stale_reads, "joint reading #n is stale");
  fault("--fault-nan-read", &a->fault_nan_reads, "joint reading #n has a NaN");
  fault("--fault-short-read", &a->fault_short_reads, "joint reading #n misses a joint");
  return [a, robot_word, backend, config]() {
    const Status resolved = ResolveRobotWord(*robot_word, backend->count() > 0, config->count() > 0, a.get());
    if (!resolved.ok()) return Fail(resolved);
    return RunFromSettings(*a);
  };
}

}  // namespace selfcal::app

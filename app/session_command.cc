// selfcal run: drives a robot through a plan and records a session (acquisition/session_runner.h).
#include "app/session_command.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "app/cli_output.h"
#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/run_configuration.h"
#include "app/commands.h"
#include "app/vendor_robots.h"
#include "io/observations_file.h"
#include "io/report_json.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"
#include "io/urdf_robot_config.h"
#include "acquisition/session_runner.h"
#include "base/terminal_text.h"
#include "liveview/live_view.h"
#include "simulation/sim_run_settings.h"
#include "simulation/sim_session.h"
#include "robot/manual_robot.h"
#include "robot/network_robot.h"
#include "session/samples.h"
#include "session/session_cleanup.h"
#include "session/session_dir.h"
#include "session/session_lock.h"
#include "session/session_snapshot.h"
#include "session/session_observations.h"
#include "session/setup_file.h"

namespace selfcal::app {

namespace {

using nlohmann::json;

std::atomic<bool> g_stop_requested{false};
extern "C" void OnStopSignal(int) { g_stop_requested.store(true); }  // R11: only sets a flag

void InstallStopHandlers() {
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

std::string UtcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

std::vector<acquisition::PlannedPose> PlanPoses(const io::TrajectoryFile& plan) {
  std::vector<acquisition::PlannedPose> poses;
  const int n = static_cast<int>(plan.poses.size());
  const int id_poses = plan.num_identification_poses > 0 ? plan.num_identification_poses : std::min(n, 15);
  for (int i = 0; i < n; ++i) {
    char id[16];
    std::snprintf(id, sizeof(id), "p%02d", i);
    poses.push_back({id, i < id_poses ? PoseRole::kIdentification : PoseRole::kVerification, plan.poses[i]});
  }
  return poses;
}


// The run settings that must not change on resume (run.json input).
json RunJson(const RunSettings& a) {
  json run = {{"format", "selfcal-run"},
          {"version", 1},
          {"robot", a.robot_backend},
          // The address is a transport detail, not an input: a controller restarted on another port is the
          // same robot (its identity is checked on resume, its limits at connect). Kept, empty, so that the
          // run.json of earlier simulated sessions is unchanged.
          {"address", ""},
          {"camera", a.camera_backend},
          {"device", a.camera_backend == "v4l2"     ? a.device
                     : a.camera_backend == "aravis" ? a.camera_mode.aravis_id
                                                    : ""},
          {"velocity_scaling", a.velocity_scaling},
          {"seed", a.seed},
          {"grey_noise", a.grey_noise},
          {"blur_px", a.blur_px},
          {"supersampling", a.supersampling},
          {"faults",
           {{"reject_moves", a.fault_reject_moves}, {"protective_stop_moves", a.fault_pstop_moves},
            {"hang_moves", a.fault_hang_moves}, {"disconnect_moves", a.fault_disconnect_moves},
            {"jog_after_moves", a.fault_jog_after_moves}, {"slow_settle_moves", a.fault_slow_settle_moves},
            {"stale_reads", a.fault_stale_reads}, {"nan_reads", a.fault_nan_reads},
            {"short_reads", a.fault_short_reads}}}};
  // The jog's delay only when not the default, so that the run.json of earlier sessions is unchanged.
  if (a.fault_jog_delay_s != RunSettings().fault_jog_delay_s) run["faults"]["jog_delay_s"] = a.fault_jog_delay_s;
  if (!a.fault_never_settle_moves.empty()) run["faults"]["never_settle_moves"] = a.fault_never_settle_moves;
  const json camera_mode = CameraModeJson(a.camera_mode);  // only when given: earlier run.json unchanged
  if (a.camera_backend != "sim" && !camera_mode.empty()) run["camera_mode"] = camera_mode;
  return run;
}

// run.json as the session records it.
std::string RunJsonText(const RunSettings& a) { return RunJson(a).dump(2) + "\n"; }

// The simulated cell of these settings, through their run.json (the recorded form an audit rebuilds from).
simulation::SimCellOptions SimCellOptionsFor(const RunSettings& a) {
  return simulation::SimCellOptionsFor(RunJsonText(a)).value();
}

// What the stages of a run share: the nominal robot, the plan, the session's inputs and, with the
// simulated robot, the simulated cell.
struct RunPlan {
  RobotModel nominal;
  std::vector<acquisition::PlannedPose> plan;
  std::optional<acquisition::PlanToCheck> plan_check;  // the whole plan file, for the preflight
  session::SessionInputs inputs;
  acquisition::PredictionModel prediction;  // the nominal robot and the setup's camera: dots named by prediction
  Result<simulation::SimCell> cell = Status::Error(ErrorCode::kInvalidInput, "no simulated cell");
};

// The backends a run drives (R12: the simulated ones are chosen explicitly and never talk to hardware).
struct Backends {
  std::unique_ptr<robot::Robot> owned_robot;
  std::unique_ptr<capture::FrameSource> owned_camera;
  std::unique_ptr<robot::Clock> owned_clock;
  robot::Robot* arm = nullptr;
  capture::FrameSource* camera = nullptr;
  robot::Clock* clock = nullptr;
  acquisition::DetectionOrderIdentifier order_identifier;
  acquisition::DotIdentifier* identifier = &order_identifier;
  std::unique_ptr<acquisition::DotIdentifier> owned_identifier;  // --identify
  std::unique_ptr<liveview::LiveView> live_view;                 // --live-view; null when off
};

// --live-view: a window showing every frame the loop looks at (liveview/live_view.h). `on` without a
// display is refused here, before any session is touched; `auto` says only why a set $DISPLAY failed.
Status OpenRunLiveView(const RunSettings& a, Backends* b) {
  Result<liveview::LiveViewMode> mode = liveview::ParseLiveViewMode(a.live_view);
  if (!mode.ok()) return mode.status();
  liveview::LiveViewOptions options;
  options.title = "selfcal run " + a.session + " (" + a.configuration + ")";
  options.log = [](const std::string& line) { std::cout << line << "\n" << std::flush; };
  std::string note;
  Result<std::unique_ptr<liveview::LiveView>> view = liveview::OpenLiveView(*mode, options, &note);
  if (!view.ok()) return view.status();
  b->live_view = std::move(view).value();
  const char* display = std::getenv("DISPLAY");
  if (!note.empty() && (b->live_view || (display != nullptr && *display != '\0'))) std::cout << note << "\n";
  return Status::Ok();
}

// Refuses backend combinations that cannot work and fills in the default velocity scaling.
Status CheckRunSettings(RunSettings* a) {
  const bool sim_robot = a->robot_backend == "sim";
  const bool sim_camera = a->camera_backend == "sim";  // with any robot: it renders the joints the robot reports
  if (sim_robot && !sim_camera) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "--backend sim needs --camera sim: the simulated arm moves only in the simulated cell");
  }
  if (sim_camera && !a->setup.empty()) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "--setup " + a->setup + " does not apply to --camera sim (nor --backend sim): the simulated "
                         "cell makes its own setup (camera, yardstick, checks); leave --setup out, or use a real camera");
  }
  if (!sim_camera && a->setup.empty()) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "--setup FILE (camera, yardstick; docs/session-format.md) is required with a real camera");
  }
  if (a->velocity_scaling < 0) a->velocity_scaling = sim_robot ? 1.0 : 0.1;
  return Status::Ok();
}

// A real camera's setup.json (--setup) into *probe, refused when its configuration is not --configuration's.
Status ReadRealSetup(const RunSettings& a, CameraMount mount, ObservationSet* probe) {
  Result<session::SessionInput> setup = session::ReadInputFile(session::kSetupFileName, a.setup);
  if (!setup.ok()) return setup.status();
  if (Status s = session::ParseSetupFile(setup->contents, a.setup, probe); !s.ok()) return s;
  if (probe->robot.mount == mount) return Status::Ok();
  return Status::Error(ErrorCode::kInvalidInput, "--setup " + a.setup + " is for configuration " +
                                                     CameraMountName(probe->robot.mount) + " (its `configuration`), "
                                                     "this run is " + a.configuration + " (--configuration)");
}

// Stage 1: the robot config, the plan and the setup (made by the simulated cell, or --setup), as the
// session's inputs.
Status LoadRunPlan(const RunSettings& a, RunPlan* run) {
  // A config naming a URDF is recorded as its converted model, so that the session stands on its own.
  Result<std::string> robot_text = io::RobotConfigTextForSession(ResolveDataPath(a.robot_config));
  if (!robot_text.ok()) return robot_text.status();
  const session::SessionInput robot_input{"robot.yaml", *robot_text};
  Result<RobotModel> nominal = io::LoadRobotModel(ResolveDataPath(a.robot_config));
  if (!nominal.ok()) return nominal.status();
  Result<CameraMount> mount = ParseConfiguration(a.configuration);
  if (!mount.ok()) return mount.status();
  ObservationSet probe;  // a real camera's setup (with its fixed camera in eye-to-hand)
  if (a.camera_backend != "sim") {
    if (Status s = ReadRealSetup(a, *mount, &probe); !s.ok()) return s;
    nominal.value().mount = *mount;
    nominal.value().base_from_cam = probe.robot.base_from_cam;
  } else {
    nominal = RobotInSimulatedCell(*nominal, a.robot_config, *mount);
    if (!nominal.ok()) return nominal.status();
  }
  run->nominal = *nominal;
  Result<session::SessionInput> plan_input = session::ReadInputFile("plan.yaml", ResolveDataPath(a.plan));
  if (!plan_input.ok()) return plan_input.status();
  // A plan for another robot is a usage error naming both; the limits are `plan --check`'s (preflight).
  Result<io::TrajectoryFile> plan_file = io::LoadTrajectoryFileForRobot(ResolveDataPath(a.plan), run->nominal, a.robot_config);
  if (!plan_file.ok()) return plan_file.status();
  if (plan_file->planned_for && plan_file->planned_for->configuration != *mount) {
    return Status::Error(ErrorCode::kInvalidInput, "plan " + a.plan + " was planned for configuration " +
                                                       CameraMountName(plan_file->planned_for->configuration) +
                                                       ", this run is " + a.configuration + " (--configuration)");
  }
  run->plan = PlanPoses(*plan_file);
  run->plan_check = acquisition::PlanToCheck{run->nominal, io::PlanSubjectOf(*plan_file)};
  // The plan check against the robot config before the simulated cell is built for the plan; the preflight
  // repeats it with the controller's limits.
  const planning::PlanCheck check = planning::CheckPlanFor(&run->nominal, run->plan_check->plan, nullptr);
  if (!check.ok) {
    return Status::Error(ErrorCode::kDegenerateData, acquisition::PreflightRefusal(acquisition::PreflightProblems(check)));
  }
  run->inputs = {robot_input, *plan_input, {"run.json", RunJsonText(a)}};
  // The simulated cell (--camera sim, with any robot) is built before the session: its setup is recorded.
  if (a.camera_backend == "sim") {
    run->cell = simulation::MakeSimCell(run->nominal, run->plan, SimCellOptionsFor(a), run->plan.front().joints_rad, 0);
    if (!run->cell.ok()) return run->cell.status();
    const ObservationSet setup = simulation::SimSetup(*run->cell);
    run->inputs.push_back({session::kSetupFileName, session::SetupFileText(setup)});
    run->prediction = {run->nominal, setup.camera, setup.pixel_noise_px};
    return Status::Ok();
  }
  Result<session::SessionInput> setup = session::ReadInputFile(session::kSetupFileName, a.setup);
  if (!setup.ok()) return setup.status();
  run->inputs.push_back(*setup);
  run->prediction = {run->nominal, probe.camera, probe.pixel_noise_px};
  return Status::Ok();
}

// A resumed simulated cell restarts where the last accepted sample of `records` left the arm
// (sim_session.h); other backends are where they are.
Status RestartSimulatedArm(const RunSettings& a, const std::vector<nlohmann::json>& records, RunPlan* run) {
  if (a.robot_backend != "sim") return Status::Ok();
  Result<session::SessionLog> log = session::ReadSessionLog(records);
  if (!log.ok()) return log.status();
  if (const session::AcceptedSample* last = log->LastAcceptedSample()) {
    simulation::RestartSimCell(&run->cell.value(), SimCellOptionsFor(a), run->plan[last->pose].joints_rad,
                               last->sim_clock_s.value_or(0));
  }
  return Status::Ok();
}

// Stage 2, --resume: opens the session (inputs compared, journal recovered, orphans moved: reported) and
// restarts the simulated arm where the last accepted sample left it (sim_session.h).
Result<session::Session> ResumeSession(const RunSettings& a, RunPlan* run) {
  Result<session::Session> opened = session::OpenSession(a.session, run->inputs, a.force_changed_config,
                                                         session::JournalLimits(), a.take_over_stale_lock);
  if (!opened.ok()) return opened.status();
  const session::OpenReport& r = opened->open_report();
  if (r.journal.truncated()) {
    std::cout << "journal: dropped a torn tail of " << r.journal.dropped_bytes << " bytes (" << r.journal.reason
              << ")\n";
  }
  for (const std::string& o : r.orphans) std::cout << "moved an unrecorded image aside: " << o << "\n";
  if (!r.stale_lock_from.empty()) std::cout << "took over the lock of a dead process: " << r.stale_lock_from << "\n";
  if (Status s = RestartSimulatedArm(a, opened->journal().records(), run); !s.ok()) return s;
  return opened;
}

// Stage 2, --resume --dry-run: the session read without changing anything (session::ReadSession: no lock
// taken, no tail truncated, no image moved); the inputs compared as a resume compares them, and what a
// resume would repair reported.
Result<session::SessionSnapshot> InspectResume(const RunSettings& a, RunPlan* run) {
  Result<session::SessionSnapshot> snapshot = session::ReadSession(a.session);
  if (!snapshot.ok()) return snapshot.status();
  const std::vector<std::string> changed = session::ChangedInputs(snapshot->manifest, run->inputs);
  if (!changed.empty() && !a.force_changed_config) return session::ChangedInputsRefusal(a.session, changed);
  for (const std::string& finding : snapshot->Findings()) std::cout << "dry run: " << finding << "\n";
  if (const std::string holder = session::LockHolderNamed(a.session); !holder.empty()) {
    std::cout << "dry run: " << a.session << "/lock names " << holder
              << ": a resume is refused while that process holds it, and takes it over only with "
                 "--take-over-stale-lock once it has ended; left unchanged\n";
  }
  if (Status s = RestartSimulatedArm(a, snapshot->records, run); !s.ok()) return s;
  return snapshot;
}

// Stage 2, a new session: created (with its parent folder) from the inputs once the run can start (the
// callback of acquisition::RunContext); never overwrites (C10). `restart` removes an interrupted creation
// with the same inputs first (nothing was recorded in it; session_cleanup.h).
Result<session::Session> CreateRunSession(const RunSettings& a, const RunPlan& run, bool restart) {
  if (restart) {
    if (Status s = session::DiscardSession(a.session, a.take_over_stale_lock); !s.ok()) return s;
  }
  const std::filesystem::path parent = std::filesystem::path(a.session).parent_path();
  if (!parent.empty()) {
    if (Status s = EnsureDirectory(parent.string()); !s.ok()) return s;
  }
  session::CreateOptions create;
  create.created_utc = UtcNow();
  create.min_free_bytes = static_cast<std::uint64_t>(run.plan.size()) * 4 * 400 * 1024;
  create.configuration = run.nominal.mount;
  return session::CreateSession(a.session, run.inputs, SELFCAL_VERSION, create);
}

// Stage 3: the robot, camera, clock and dot identifier of the run.
Status MakeBackends(const RunSettings& a, RunPlan* run, Backends* b) {
  if (!a.identify.method.empty()) {  // acquisition/identifiers.h; the reference dots come from setup.json
    std::string setup_text;
    for (const session::SessionInput& input : run->inputs) {
      if (input.name == session::kSetupFileName) setup_text = input.contents;
    }
    auto chosen = MakeIdentifier(a.identify, "order", setup_text, a.setup.empty() ? "setup.json" : a.setup);
    if (!chosen.ok()) return chosen.status();
    b->owned_identifier = std::move(chosen).value();
  }
  if (a.robot_backend == "sim") {
    b->arm = run->cell->robot.get();
    b->camera = run->cell->camera.get();
    b->clock = run->cell->clock.get();
    b->identifier = b->owned_identifier ? b->owned_identifier.get() : run->cell->identifier.get();
    return Status::Ok();
  }
  b->owned_clock = std::make_unique<robot::MonotonicClock>();
  b->clock = b->owned_clock.get();
  const auto log = [](const std::string& line) {
    ClearProgressLine();
    std::cout << TerminalSafe(line) << "\n";
  };
  if (a.robot_backend == "network") {
    const size_t colon = a.address.rfind(':');
    const int port = colon == std::string::npos ? -1 : PortNumber(a.address.substr(colon + 1));
    if (port < 0) return Status::Error(ErrorCode::kInvalidInput, "--address must be HOST:PORT, not \"" + a.address + "\"");
    robot::NetworkRobotOptions options;  // everything checked at connect against the robot config
    options.config_limits = ManualJointLimits(run->nominal);
    options.log = log;
    b->owned_robot = std::make_unique<robot::NetworkRobot>(a.address.substr(0, colon), port, options);
  } else if (a.robot_backend == "ur" || a.robot_backend == "fanuc") {
    Result<std::unique_ptr<robot::Robot>> vendor = MakeVendorRobot(a, ManualJointLimits(run->nominal), log);
    if (!vendor.ok()) return vendor.status();
    b->owned_robot = std::move(vendor).value();
  } else if (a.robot_backend == "manual") {
    b->owned_robot = std::make_unique<robot::ManualRobot>(std::cin, JsonMode() ? std::cerr : std::cout,
                                                          ManualJointLimits(run->nominal), *b->clock);
  } else {
    return Status::Error(ErrorCode::kInvalidInput, "--robot must be sim, network, manual, ur or fanuc");
  }
  b->arm = b->owned_robot.get();
  if (b->owned_identifier) b->identifier = b->owned_identifier.get();
  if (a.camera_backend == "sim") {  // the simulated cell's camera at the joints this robot reports
    simulation::FollowReportedJoints(&run->cell.value(), SimCellOptionsFor(a), b->arm, run->plan.front().joints_rad);
    b->camera = run->cell->camera.get();
    std::cout << "camera sim: the simulated cell of seed " << a.seed << " (run.json), rendered at the joints the "
              << a.robot_backend << " robot reports\n";
    if (!b->owned_identifier) b->identifier = run->cell->identifier.get();
    return Status::Ok();
  }
  Result<std::unique_ptr<capture::FrameSource>> camera = MakeLiveCamera(a.camera_backend, a.device, a.camera_mode);
  if (!camera.ok()) return camera.status();
  b->owned_camera = std::move(camera).value();
  b->camera = b->owned_camera.get();
  return Status::Ok();
}

// The session directory a run writes into, as found before anything is created.
struct SessionTarget {
  std::optional<session::Session> opened;  // --resume of a recorded session
  std::optional<session::SessionSnapshot> inspected;  // --resume --dry-run: read only
  bool restart_creation = false;           // --resume of an interrupted creation: made again (same inputs)
};

// Stage 2: a new run needs an absent or empty directory (C10; it is created once the run can start); a
// resume opens the session (ResumeSession), or completes an interrupted creation made with the same
// inputs (session_cleanup.h).
Status PrepareSession(const RunSettings& a, RunPlan* run, Backends* backends, SessionTarget* out) {
  Result<session::SessionDirInspection> dir = session::InspectSessionDir(a.session);
  if (!dir.ok()) return dir.status();
  const session::SessionDirState state = dir->state;
  const bool unrecorded =
      state == session::SessionDirState::kInterruptedCreation || state == session::SessionDirState::kNothingRecorded;
  if (!a.resume) {
    if (state == session::SessionDirState::kAbsent || state == session::SessionDirState::kEmpty) return Status::Ok();
    return Status::Error(ErrorCode::kInvalidInput,
                         "session directory " + a.session +
                             " exists and is not empty: a session is never overwritten; " +
                             (unrecorded ? "it holds no recorded sample: `selfcal run --resume` with the same options "
                                           "completes it, `selfcal session discard " + a.session + "` removes it"
                                         : std::string("choose a new directory")));
  }
  if (state == session::SessionDirState::kInterruptedCreation) {
    std::string differing;
    for (const std::string& name : session::DifferingInputs(*dir, run->inputs)) {
      differing += (differing.empty() ? "" : ", ") + name;
    }
    if (!differing.empty() && !a.force_changed_config) {
      return Status::Error(ErrorCode::kInvalidInput,
                           "session " + a.session + ": its creation was interrupted with other inputs (" + differing +
                               "); run with the same files, or remove it with `selfcal session discard " + a.session +
                               "`");
    }
    std::cout << "session " << a.session << ": its creation was interrupted (no session.json, nothing recorded); "
              << (a.dry_run ? "a resume would create it again (dry run: left as it is)\n"
                            : "it is created again once the run can start\n");
    out->restart_creation = true;
    return Status::Ok();
  }
  if (a.dry_run) {
    Result<session::SessionSnapshot> inspected = InspectResume(a, run);
    if (!inspected.ok()) return inspected.status();
    out->inspected.emplace(std::move(inspected).value());
    return a.robot_backend == "sim" ? MakeBackends(a, run, backends) : Status::Ok();
  }
  Result<session::Session> opened = ResumeSession(a, run);
  if (!opened.ok()) return opened.status();
  out->opened.emplace(std::move(opened).value());
  // The resumed simulated cell was restarted: its robot, camera and clock are new objects.
  return a.robot_backend == "sim" ? MakeBackends(a, run, backends) : Status::Ok();
}

// --json: what the session loop did (this run's samples, skips and faults) and the session directory.
void RecordRunFigures(const RunSettings& a, const acquisition::RunReport& report, bool session_exists) {
  OutputDocument()["run"] = {{"outcome", acquisition::RunOutcomeName(report.outcome)},
                             {"message", report.message},
                             {"session", a.session},
                             {"first_pose", report.first_pose},
                             {"samples_accepted", report.accepted},
                             {"samples_skipped", report.skips},
                             {"faults", report.faults},
                             {"frames_grabbed", report.frames_grabbed},
                             {"frames_tracked", report.frames_tracked},
                             {"halt_reason", report.halt_reason.empty() ? nlohmann::json() : json(report.halt_reason)},
                             {"dry_run", a.dry_run}};
  const bool dry_run = a.dry_run && report.outcome == acquisition::RunOutcome::kRefused;
  SetOutcome(dry_run ? "dry_run" : acquisition::RunOutcomeName(report.outcome));
  if (session_exists) AddOutputFile("session", a.session);
}

// Stage 4: the session loop (acquisition::RunSession) and what it did; returns the exit code.
// `session` is the session to continue, or null: then `create` makes it once the run can start.
int DriveSession(const RunSettings& a, const RunPlan& run, const Backends& b, const SessionTarget& target,
                 session::Session* session, const std::function<Result<session::Session*>()>& create,
                 const std::optional<session::Session>& created) {
  const bool sim_robot = a.robot_backend == "sim";
  InstallStopHandlers();
  acquisition::RunOptions options;
  options.safety.velocity_scaling = a.velocity_scaling;
  options.plan_check = run.plan_check;
  options.journal_sim_clock = sim_robot;
  options.mode = sim_robot ? "simulated" : a.robot_backend;
  options.revisit_skipped = a.revisit_skipped;
  options.dry_run = a.dry_run;  // no camera opened
  if (sim_robot) options.settle.min_dwell_s = 0.6;  // > the simulated ring-down cutoff (resume determinism)
  acquisition::RunContext context;
  context.robot = b.arm;
  context.camera = b.camera;
  context.clock = b.clock;
  context.session = session;
  context.create_session = create;
  if (target.inspected) context.dry_run_of = &*target.inspected;  // a dry run of a resume: read only
  context.identifier = b.identifier;
  context.prediction = &run.prediction;
  context.stop_requested = &g_stop_requested;
  const bool dry_run = a.dry_run;
  context.confirm = [dry_run](const std::string& preview, const robot::RobotIdentity& identity) {
    return ConfirmOnTerminal(preview, identity, dry_run);
  };
  context.log = [](const std::string& line) {
    ClearProgressLine();
    std::cout << TerminalSafe(line) << "\n" << std::flush;
  };
  context.progress = Progress();
  if (liveview::LiveView* view = b.live_view.get()) {
    context.observe = [view](const acquisition::FrameView& frame) { view->Show(frame); };
  }
  const acquisition::RunReport report = acquisition::RunSession(run.plan, context, options);
  RecordRunFigures(a, report, session != nullptr || created.has_value());
  if (a.dry_run && report.outcome == acquisition::RunOutcome::kRefused && report.preview.size() > 0 &&
      report.message.rfind("not confirmed", 0) == 0) {
    return 0;
  }
  if (report.outcome == acquisition::RunOutcome::kRefused) {  // nothing moved: the refusal on stderr
    std::cerr << "selfcal: run: refused: " << TerminalSafe(report.message) << "\n";
    RecordError(report.message);
  } else {
    std::cout << "run: " << acquisition::RunOutcomeName(report.outcome) << ": " << TerminalSafe(report.message)
              << "\n";
  }
  std::cout << "this run: " << report.accepted << " samples accepted from pose " << report.first_pose << ", "
            << report.frames_grabbed << " frames grabbed, " << report.frames_tracked << " tracked";
  for (const auto& [reason, n] : report.skips) std::cout << ", skipped " << reason << " x" << n;
  for (const auto& [kind, n] : report.faults) std::cout << ", fault " << kind << " x" << n;
  std::cout << "\nnamed by prediction: " << report.named_by_prediction << " dots, " << report.dropped_by_prediction
            << " tracked dots dropped, " << report.ambiguous_by_prediction << " ambiguous detections, "
            << report.prediction_uncorrected << " frames uncorrected";
  if (report.named_later > 0) {
    std::cout << "; named later in the recorded frames: " << report.named_later << " dots in "
              << report.samples_named_later << " samples";
  }
  std::cout << "\n";
  if (b.live_view) {
    std::cout << "live view: " << b.live_view->frames_drawn() << " frames drawn, " << b.live_view->frames_throttled()
              << " frames of moves not redrawn (at most 15 a second)\n";
  }
  if (report.outcome == acquisition::RunOutcome::kTooFewSamples) {
    std::cout << "NOT COMPLETE: too few samples to calibrate. Look at the skipped poses' frames in " << a.session
              << "/images/rejected/, fix the cause, then: selfcal run --resume --session " << a.session
              << " --revisit-skipped 1 (same options)\n";
  }
  const bool halted =
      report.outcome == acquisition::RunOutcome::kHalted || report.outcome == acquisition::RunOutcome::kInterrupted;
  if (halted && report.halt_reason.empty()) {  // before the first motion command (connect, identity, camera)
    std::cout << "HALTED before any motion command: nothing was sent to the arm. "
              << (session == nullptr && !created ? "No session was created; run the same command again"
                                                          : "Continue with: selfcal run --resume --session " +
                                                                a.session + " (same options)")
              << " once the cause is fixed\n";
  } else if (halted) {
    std::cout << (report.stop_sent ? "HALTED. The robot was told to stop."
                                   : "HALTED. The stop command could not be sent, was refused or was not "
                                     "acknowledged: stop the arm at its controller.")
              << " Check the cell, then continue with: selfcal run --resume --session " << a.session
              << " (same options)\n";
  }
  return static_cast<int>(ExitCodeFor(report.error));
}

}  // namespace

namespace {

// No --plan: the robot's own shipped trajectory, resolved before anything is recorded (run.json names it).
Status ResolvePlanPath(RunSettings* a) {
  if (!a->plan.empty()) return Status::Ok();
  Result<RobotModel> robot = io::LoadRobotModel(ResolveDataPath(a->robot_config));
  if (!robot.ok()) return robot.status();
  Result<std::string> plan = TrajectoryForRobot("", robot->name, a->robot_config);
  if (!plan.ok()) return plan.status();
  a->plan = *plan;
  return Status::Ok();
}

}  // namespace

int RunFromSettings(RunSettings a, std::unique_ptr<sim::SimResult>* world) {
  if (Status s = CheckRunSettings(&a); !s.ok()) return Fail(s);
  if (Status s = ResolvePlanPath(&a); !s.ok()) return Fail(s);
  if (a.resume) {  // before any input is read: a session keeps the configuration it was recorded in
    Result<CameraMount> mount = ParseConfiguration(a.configuration);
    if (!mount.ok()) return Fail(mount.status());
    if (Status s = CheckResumeConfiguration(a.session, *mount); !s.ok()) return Fail(s);
  }
  RunPlan run;
  if (Status s = LoadRunPlan(a, &run); !s.ok()) return Fail(s);
  if (run.nominal.mount == CameraMount::kEyeToHand) {
    std::cout << "configuration eye_to_hand: the camera fixed at " << run.nominal.base_from_cam.translation.transpose() * 1e3
              << " mm in the base frame, the dots on the flange\n";
  }
  Backends backends;  // a bad --address is refused before any session is touched
  if (Status s = MakeBackends(a, &run, &backends); !s.ok()) return Fail(s);
  if (Status s = OpenRunLiveView(a, &backends); !s.ok()) return Fail(s);
  SessionTarget target;
  if (Status s = PrepareSession(a, &run, &backends, &target); !s.ok()) return Fail(s);
  std::optional<session::Session> created;
  auto create = [&]() -> Result<session::Session*> {
    Result<session::Session> made = CreateRunSession(a, run, target.restart_creation);
    if (!made.ok()) return made.status();
    created.emplace(std::move(made).value());
    return &*created;
  };
  const int code = DriveSession(a, run, backends, target, target.opened ? &*target.opened : nullptr, create, created);
  if (world != nullptr && a.robot_backend == "sim") *world = std::move(run.cell.value().world);
  return code;
}

}  // namespace selfcal::app

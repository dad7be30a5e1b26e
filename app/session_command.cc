// selfcal run: drives a robot through a plan and records a session (acquisition/session_runner.h).
// selfcal calibrate SESSION: the offline solve of a recorded session.
#include "app/session_command.h"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "app/cli_util.h"
#include "app/commands.h"
#include "base/atomic_file.h"
#include "capture/v4l2_camera.h"
#include "io/observations_file.h"
#include "io/report_json.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"
#include "acquisition/session_runner.h"
#include "simulation/sim_session.h"
#include "robot/manual_robot.h"
#include "robot/network_robot.h"
#include "session/samples.h"
#include "session/session_dir.h"

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

Result<std::string> ReadWhole(const std::string& path) {
  Result<std::string> bytes = ReadFileCapped(path, session::kMaxInputBytes);
  if (!bytes.ok()) return Status::Error(ExitCode::kUsage, "cannot read " + path + ": " + bytes.status().message());
  return bytes;
}

json KnownDistancesJson(const std::vector<KnownDistance>& distances) {
  json a = json::array();
  for (const KnownDistance& d : distances) a.push_back({{"dot_a", d.dot_a}, {"dot_b", d.dot_b}, {"length_m", d.length_m}});
  return a;
}

// setup.json: what a calibration needs beside the robot and the samples (docs/session-format.md).
json SetupJson(const ObservationSet& setup) {
  const CameraIntrinsics& c = setup.camera;
  return {{"format", "selfcal-session-setup"},
          {"version", 1},
          {"camera", {{"width_px", c.width_px}, {"height_px", c.height_px}, {"fx_px", c.fx_px}, {"mu", c.mu},
                      {"cx_px", c.cx_px}, {"cy_px", c.cy_px}, {"k1", c.k1}}},
          {"pixel_noise_px", setup.pixel_noise_px},
          {"yardsticks", KnownDistancesJson(setup.yardsticks)},
          {"check_distances", KnownDistancesJson(setup.check_distances)}};
}

Status ParseSetup(const std::string& text, const std::string& name, ObservationSet* set) {
  auto bad = [&](const std::string& why) { return Status::Error(ExitCode::kUsage, name + ": " + why); };
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) return bad("not a JSON object");
  if (j.value("format", "") != "selfcal-session-setup" || j.value("version", 0) != 1) {
    return bad("format must be selfcal-session-setup version 1");
  }
  try {
    const json& c = j.at("camera");
    set->camera.width_px = c.at("width_px").get<int>();
    set->camera.height_px = c.at("height_px").get<int>();
    set->camera.fx_px = c.at("fx_px").get<double>();
    set->camera.mu = c.at("mu").get<double>();
    set->camera.cx_px = c.at("cx_px").get<double>();
    set->camera.cy_px = c.at("cy_px").get<double>();
    set->camera.k1 = c.at("k1").get<double>();
    set->pixel_noise_px = j.at("pixel_noise_px").get<double>();
    for (const char* key : {"yardsticks", "check_distances"}) {
      std::vector<KnownDistance>& out = std::string(key) == "yardsticks" ? set->yardsticks : set->check_distances;
      for (const json& d : j.at(key)) {
        out.push_back({d.at("dot_a").get<int>(), d.at("dot_b").get<int>(), d.at("length_m").get<double>()});
      }
    }
  } catch (const json::exception& e) {
    return bad(std::string("missing or mistyped key: ") + e.what());
  }
  if (!(set->camera.fx_px > 0) || set->camera.width_px <= 0 || set->camera.height_px <= 0 || !(set->pixel_noise_px > 0)) {
    return bad("camera size, fx_px and pixel_noise_px must be positive");
  }
  return Status::Ok();
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
  return {{"format", "selfcal-run"},
          {"version", 1},
          {"robot", a.robot_backend},
          {"address", a.robot_backend == "network" ? a.address : ""},
          {"camera", a.camera_backend},
          {"device", a.camera_backend == "v4l2" ? a.device : ""},
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
}

simulation::SimCellOptions SimCellOptionsFor(const RunSettings& a) {
  simulation::SimCellOptions o;
  o.world.world_seed = a.seed;
  o.world.noise_seed = a.seed;
  o.world.pixel_noise_px = 0.02;  // the centroid noise the solvers are told (measured 0.01 px at grey noise 2)
  o.camera.render.noise_std_grey = a.grey_noise;
  o.camera.render.blur_sigma_px = a.blur_px;
  o.camera.render.supersampling = a.supersampling;
  auto set = [](const std::vector<int>& v) { return std::set<int>(v.begin(), v.end()); };
  o.faults.reject_moves = set(a.fault_reject_moves);
  o.faults.protective_stop_moves = set(a.fault_pstop_moves);
  o.faults.hang_moves = set(a.fault_hang_moves);
  o.faults.disconnect_moves = set(a.fault_disconnect_moves);
  o.faults.jog_after_moves = set(a.fault_jog_after_moves);
  o.faults.slow_settle_moves = set(a.fault_slow_settle_moves);
  o.faults.stale_reads = set(a.fault_stale_reads);
  o.faults.nan_reads = set(a.fault_nan_reads);
  o.faults.short_reads = set(a.fault_short_reads);
  return o;
}

// Typed confirmation before a real backend moves (R1): the operator types the robot's serial.
bool ConfirmOnTerminal(const std::string& preview, const robot::RobotIdentity& identity, bool dry_run) {
  std::cout << preview;
  if (dry_run) {
    std::cout << "dry run: nothing moved, no command was sent to the robot\n";
    return false;
  }
  if (!identity.real_hardware) {
    std::cout << "simulated robot: armed without confirmation\n";
    return true;
  }
  std::cout << "This moves a REAL robot (" << identity.model << ", serial " << identity.serial
            << "). Type the serial to arm, anything else to cancel: " << std::flush;
  std::string answer;
  if (!std::getline(std::cin, answer)) return false;
  return answer == identity.serial;
}

}  // namespace

int RunFromSettings(RunSettings a, std::unique_ptr<sim::SimResult>* world) {
  const bool sim_robot = a.robot_backend == "sim";
  const bool sim_camera = a.camera_backend == "sim";
  if (sim_camera != sim_robot) {
    return Fail(Status::Error(ExitCode::kUsage,
                              "--camera sim renders what the simulated arm sees: it needs --robot sim, and --robot "
                              "sim needs --camera sim (C9)"));
  }
  if (!sim_camera && a.setup.empty()) {
    return Fail(Status::Error(ExitCode::kUsage, "--setup FILE (camera, yardstick; docs/session-format.md) is required "
                                                "with a real camera (C2)"));
  }
  if (a.velocity_scaling < 0) a.velocity_scaling = sim_robot ? 1.0 : 0.1;
  Result<std::string> robot_text = ReadWhole(ResolveDataPath(a.robot_config));
  if (!robot_text.ok()) return Fail(robot_text.status());
  Result<RobotModel> nominal = io::LoadRobotModel(ResolveDataPath(a.robot_config));
  if (!nominal.ok()) return Fail(nominal.status());
  Result<std::string> plan_text = ReadWhole(ResolveDataPath(a.plan));
  if (!plan_text.ok()) return Fail(plan_text.status());
  Result<io::TrajectoryFile> plan_file = io::LoadTrajectoryFile(ResolveDataPath(a.plan), *nominal);
  if (!plan_file.ok()) return Fail(plan_file.status());
  const std::vector<acquisition::PlannedPose> plan = PlanPoses(*plan_file);

  // Resume: the simulated arm restarts where the last accepted sample left it (sim_session.h).
  Eigen::VectorXd start_joints = plan.front().joints_rad;
  double start_time_s = 0;
  std::optional<session::Session> session;
  session::SessionInputs inputs = {{"robot.yaml", *robot_text}, {"plan.yaml", *plan_text},
                                   {"run.json", RunJson(a).dump(2) + "\n"}};
  // The simulated cell (built before the session so that its setup can be recorded).
  Result<simulation::SimCell> cell = Status::Error(ExitCode::kUsage, "no simulated cell");
  std::string setup_text;
  if (sim_robot) {
    cell = simulation::MakeSimCell(*nominal, plan, SimCellOptionsFor(a), start_joints, start_time_s);
    if (!cell.ok()) return Fail(cell.status());
    setup_text = SetupJson(simulation::SimSetup(*cell)).dump(2) + "\n";
  } else {
    Result<std::string> text = ReadWhole(a.setup);
    if (!text.ok()) return Fail(text.status());
    ObservationSet probe;
    if (Status s = ParseSetup(*text, a.setup, &probe); !s.ok()) return Fail(s);
    setup_text = *text;
  }
  inputs.push_back({"setup.json", setup_text});

  if (a.resume) {
    Result<session::Session> opened = session::OpenSession(a.session, inputs, a.force_changed_config);
    if (!opened.ok()) return Fail(opened.status());
    session.emplace(std::move(opened).value());
    const session::OpenReport& r = session->open_report();
    if (r.journal.truncated()) {
      std::cout << "journal: dropped a torn tail of " << r.journal.dropped_bytes << " bytes (" << r.journal.reason
                << ")\n";
    }
    for (const std::string& o : r.orphans) std::cout << "moved an unrecorded image aside: " << o << "\n";
    if (!r.stale_lock_from.empty()) std::cout << "took over the lock of a dead process: " << r.stale_lock_from << "\n";
    Result<session::SessionLog> log = session::ReadSessionLog(session->journal().records());
    if (!log.ok()) return Fail(log.status());
    if (sim_robot) {
      if (const session::AcceptedSample* last = log->LastAcceptedSample()) {
        start_joints = plan[last->pose].joints_rad;
        start_time_s = last->sim_clock_s.value_or(0);
        simulation::RestartSimCell(&cell.value(), SimCellOptionsFor(a), start_joints, start_time_s);
      }
    }
  } else {
    const std::filesystem::path parent = std::filesystem::path(a.session).parent_path();
    if (!parent.empty()) {
      if (Status s = EnsureDirectory(parent.string()); !s.ok()) return Fail(s);
    }
    session::CreateOptions create;
    create.created_utc = UtcNow();
    create.min_free_bytes = static_cast<std::uint64_t>(plan.size()) * 4 * 400 * 1024;
    Result<session::Session> created = session::CreateSession(a.session, inputs, SELFCAL_VERSION, create);
    if (!created.ok()) return Fail(created.status());
    session.emplace(std::move(created).value());
  }

  // Backends (R12: the simulated ones are chosen explicitly and never talk to hardware).
  std::unique_ptr<robot::Robot> owned_robot;
  std::unique_ptr<capture::FrameSource> owned_camera;
  std::unique_ptr<robot::Clock> owned_clock;
  robot::Robot* arm = nullptr;
  capture::FrameSource* camera = nullptr;
  robot::Clock* clock = nullptr;
  acquisition::DetectionOrderIdentifier order_identifier;
  acquisition::DotIdentifier* identifier = &order_identifier;
  if (sim_robot) {
    arm = cell->robot.get();
    camera = cell->camera.get();
    clock = cell->clock.get();
    identifier = cell->identifier.get();
  } else {
    owned_clock = std::make_unique<robot::MonotonicClock>();
    clock = owned_clock.get();
    if (a.robot_backend == "network") {
      const size_t colon = a.address.rfind(':');
      if (colon == std::string::npos) return Fail(Status::Error(ExitCode::kUsage, "--address must be HOST:PORT"));
      robot::NetworkRobotOptions options;
      owned_robot = std::make_unique<robot::NetworkRobot>(a.address.substr(0, colon),
                                                          std::stoi(a.address.substr(colon + 1)), options);
    } else if (a.robot_backend == "manual") {
      robot::JointLimits limits;
      const int n = nominal->num_joints();
      limits.lower_rad.resize(n);
      limits.upper_rad.resize(n);
      for (int j = 0; j < n; ++j) {
        limits.lower_rad[j] = nominal->limits[j].min_rad;
        limits.upper_rad[j] = nominal->limits[j].max_rad;
      }
      limits.max_velocity_rad_s = Eigen::VectorXd::Constant(n, 0.5);  // the operator moves it; only for timing
      owned_robot = std::make_unique<robot::ManualRobot>(std::cin, std::cout, limits, *clock);
    } else {
      return Fail(Status::Error(ExitCode::kUsage, "--robot must be sim, network or manual"));
    }
    arm = owned_robot.get();
    capture::V4l2Options options;
    options.device = a.device;
    owned_camera = std::make_unique<capture::V4l2Camera>(options);
    camera = owned_camera.get();
  }

  InstallStopHandlers();
  acquisition::RunOptions options;
  options.safety.velocity_scaling = a.velocity_scaling;
  options.journal_sim_clock = sim_robot;
  options.mode = sim_robot ? "simulated" : a.robot_backend;
  if (sim_robot) options.settle.min_dwell_s = 0.6;  // > the simulated ring-down cutoff (resume determinism)
  acquisition::RunContext context;
  context.robot = arm;
  context.camera = camera;
  context.clock = clock;
  context.session = &*session;
  context.identifier = identifier;
  context.stop_requested = &g_stop_requested;
  const bool dry_run = a.dry_run;
  context.confirm = [dry_run](const std::string& preview, const robot::RobotIdentity& identity) {
    return ConfirmOnTerminal(preview, identity, dry_run);
  };
  context.log = [](const std::string& line) { std::cout << line << "\n" << std::flush; };
  const acquisition::RunReport report = acquisition::RunSession(plan, context, options);
  if (a.dry_run && report.outcome == acquisition::RunOutcome::kRefused && report.preview.size() > 0 &&
      report.message.rfind("not confirmed", 0) == 0) {
    return 0;
  }
  std::cout << "run: " << acquisition::RunOutcomeName(report.outcome) << ": " << report.message << "\n";
  std::cout << "this run: " << report.accepted << " samples accepted from pose " << report.first_pose << ", "
            << report.frames_grabbed << " frames grabbed, " << report.frames_tracked << " tracked";
  for (const auto& [reason, n] : report.skips) std::cout << ", skipped " << reason << " x" << n;
  for (const auto& [kind, n] : report.faults) std::cout << ", fault " << kind << " x" << n;
  std::cout << "\n";
  if (report.outcome == acquisition::RunOutcome::kHalted || report.outcome == acquisition::RunOutcome::kInterrupted) {
    std::cout << "HALTED. The robot was told to stop. Check the cell, then continue with: selfcal run --resume "
                 "--session "
              << a.session << " (same options)\n";
  }
  if (world != nullptr && sim_robot) *world = std::move(cell.value().world);
  return static_cast<int>(report.exit_code);
}

bool IsSessionDirectory(const std::string& path) {
  struct stat st {};
  return ::stat((std::filesystem::path(path) / session::kManifestFileName).c_str(), &st) == 0;
}

Result<ObservationSet> LoadSessionObservations(const std::string& session_path, nlohmann::json* summary) {
  Result<session::Session> opened = session::OpenSession(session_path, {}, false);
  if (!opened.ok()) return opened.status();
  const session::Session& s = *opened;
  Result<session::SessionLog> log = session::ReadSessionLog(s.journal().records());
  if (!log.ok()) return log.status();
  if (summary != nullptr) {
    *summary = {{"path", session_path},
                {"session_id", s.manifest().session_id},
                {"poses_planned", log->num_poses},
                {"samples_accepted", log->NumAccepted()},
                {"resumes", log->resumes},
                {"finished", log->finished},
                {"skips_by_reason", log->skips_by_reason},
                {"faults_by_kind", log->faults_by_kind},
                {"halts_by_reason", log->halts_by_reason}};
  }
  if (Status v = session::VerifySampleImages(s, *log); !v.ok()) return v;
  Result<std::string> setup_text = s.ReadInput("setup.json");
  if (!setup_text.ok()) return setup_text.status();
  ObservationSet set;
  if (Status p = ParseSetup(*setup_text, session_path + "/inputs/setup.json", &set); !p.ok()) return p;
  Result<RobotModel> robot =
      io::LoadRobotModel((std::filesystem::path(session_path) / session::kInputsDirName / "robot.yaml").string());
  if (!robot.ok()) return robot.status();
  set.robot = *robot;
  for (const std::optional<session::AcceptedSample>& sample : log->accepted) {
    if (!sample) continue;
    PoseObservation pose;
    pose.id = sample->id;
    pose.role = sample->role;
    pose.joints_rad = Eigen::Map<const Eigen::VectorXd>(sample->joints_rad.data(),
                                                        static_cast<Eigen::Index>(sample->joints_rad.size()));
    for (const session::SampleDot& d : sample->dots) pose.dots_px[d.id] = {d.u_px, d.v_px};
    set.poses.push_back(std::move(pose));
  }
  if (set.PosesWithRole(PoseRole::kIdentification).size() < 2) {
    return Status::Error(ExitCode::kDegenerateData, "session " + session_path + " has " +
                                                        std::to_string(set.poses.size()) +
                                                        " accepted samples: too few to calibrate");
  }
  if (const std::string problems = set.Validate(); !problems.empty()) {
    return Status::Error(ExitCode::kDegenerateData, "session " + session_path + ": " + problems);
  }
  return set;
}

Command AddRunCommand(CLI::App& app) {
  auto a = std::make_shared<RunSettings>();
  CLI::App* cmd = app.add_subcommand("run", "Drive a robot through a plan and record a session directory");
  cmd->add_option("--session", a->session, "Session directory (created; never overwritten)")->required();
  cmd->add_flag("--resume", a->resume, "Continue a session after a stop or crash (checks every input's hash)");
  cmd->add_flag("--force-resume-with-changed-config", a->force_changed_config,
                "Resume although an input differs from the recorded one (C9)");
  cmd->add_flag("--dry-run", a->dry_run, "Check the plan and print the preview; send no motion command");
  cmd->add_option("--robot-config", a->robot_config, "Nominal robot config");
  cmd->add_option("--plan", a->plan, "Plan (trajectory file)");
  cmd->add_option("--setup", a->setup, "Camera, yardstick and checks (docs/session-format.md); not with sim");
  cmd->add_option("--robot", a->robot_backend, "Robot backend")->check(CLI::IsMember({"sim", "network", "manual"}));
  cmd->add_option("--address", a->address, "network backend: HOST:PORT (docs/robot-protocol.md)");
  cmd->add_option("--camera", a->camera_backend, "Camera backend")->check(CLI::IsMember({"sim", "v4l2"}));
  cmd->add_option("--device", a->device, "v4l2 camera device");
  cmd->add_option("--velocity-scaling", a->velocity_scaling,
                  "Fraction of the joint velocity limits (default 1 simulated, 0.1 real: R1)")
      ->check(CLI::Range(1e-3, 1.0));
  cmd->add_option("--seed", a->seed, "sim: world, noise and robot seed");
  cmd->add_option("--grey-noise", a->grey_noise, "sim: pixel noise std, grey levels")->check(CLI::Range(0.0, 50.0));
  cmd->add_option("--blur-px", a->blur_px, "sim: Gaussian blur sigma, px")->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--supersampling", a->supersampling, "sim: samples per pixel side")->check(CLI::Range(1, 8));
  auto fault = [&](const char* name, std::vector<int>* v, const char* what) {
    cmd->add_option(name, *v, what)->delimiter(',')->group("Simulated faults (sim robot, 0-based call counts)");
  };
  fault("--fault-reject-move", &a->fault_reject_moves, "R5: reject move #k");
  fault("--fault-protective-stop-move", &a->fault_pstop_moves, "R9: protective stop half way through move #k");
  fault("--fault-hang-move", &a->fault_hang_moves, "R6: move #k never finishes");
  fault("--fault-disconnect-move", &a->fault_disconnect_moves, "R10: connection lost during move #k");
  fault("--fault-jog-after-move", &a->fault_jog_after_moves, "R4: someone jogs the arm after move #k");
  fault("--fault-slow-settle-move", &a->fault_slow_settle_moves, "R7: move #k rings 20x longer");
  fault("--fault-stale-read", &a->fault_stale_reads, "R8: joint reading #n is stale");
  fault("--fault-nan-read", &a->fault_nan_reads, "R8: joint reading #n has a NaN");
  fault("--fault-short-read", &a->fault_short_reads, "R8: joint reading #n misses a joint");
  return [a]() { return RunFromSettings(*a); };
}

}  // namespace selfcal::app

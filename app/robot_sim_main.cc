// selfcal-robot-sim: the simulated robot (robot/simulated_robot.h) served over the robot line protocol
// (docs/robot-protocol.md) on 127.0.0.1, moving in real time, with the injectable faults of
// SimulatedRobotFaults on the command line. For running the network backend without an arm, and as a
// reference peer for anyone writing a protocol server or client. SIGINT and SIGTERM stop it cleanly
// (the arm is stopped, the socket closed, exit 0).
#include <atomic>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/exit_codes.h"
#include "app/fake_main.h"
#include "base/install_layout.h"
#include "base/status.h"
#include "io/robot_config.h"
#include "io/trajectory_file.h"
#include "robot/clock.h"
#include "robot/robot_server.h"
#include "robot/simulated_robot.h"

namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

struct Args {
  std::string robot = "config/robots/puma560.yaml";
  int port = 0;
  double max_velocity_deg_s = 60;
  std::vector<double> initial_joints_deg;
  std::string start_at_plan;  // the first pose of this trajectory file
  std::string serial;
  std::string calibration_id;
  uint64_t seed = 0;
  double latency_s = 0.05;
  double encoder_noise_deg = 0;
  std::vector<int> reject, hang, protective_stop, emergency_stop, drop_connection, jog_after, slow_settle, never_settle;
  std::vector<int> stale_read, nan_read, short_read;
  double jog_deg = 0;  // 0: the default jog (0.02 rad on joint 1)
};

int Fail(const selfcal::Status& status) {
  std::cerr << "selfcal-robot-sim: " << status.ToString() << "\n";
  return static_cast<int>(selfcal::app::ExitCodeFor(status.code()));
}

std::set<int> AsSet(const std::vector<int>& indices) { return std::set<int>(indices.begin(), indices.end()); }

void AddFaultOption(CLI::App& app, const std::string& name, std::vector<int>* indices, const std::string& help) {
  app.add_option(name, *indices, help + " (0-based; repeat or separate by commas)")
      ->delimiter(',')
      ->check(CLI::NonNegativeNumber);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace selfcal;
  CLI::App app{"selfcal-robot-sim: a simulated robot served over the selfcal robot line protocol on 127.0.0.1"};
  Args args;
  app.add_option("--robot", args.robot, "Robot config (joint count, limits and model name)");
  app.add_option("--port", args.port, "TCP port on 127.0.0.1 (0: any free port)")->check(CLI::Range(0, 65535));
  app.add_option("--max-velocity-deg-s", args.max_velocity_deg_s, "Velocity limit of every joint (deg/s)")
      ->check(CLI::Range(1e-3, 1e4));
  app.add_option("--initial-joints-deg", args.initial_joints_deg, "Start joints (deg; default 0, or mid-range)")
      ->delimiter(',');
  app.add_option("--start-at-plan", args.start_at_plan,
                 "Start at the first pose of this trajectory file (the plan a rehearsal runs: `selfcal run "
                 "--backend network --camera sim`)")
      ->excludes("--initial-joints-deg");
  app.add_option("--serial", args.serial, "Serial reported in HELLO (default sim-<seed>)");
  app.add_option("--calibration-id", args.calibration_id, "Calibration id reported in HELLO");
  app.add_option("--seed", args.seed, "Seed of the encoder noise");
  app.add_option("--latency-s", args.latency_s, "Delay from MOVE to motion (s)")->check(CLI::Range(0.0, 10.0));
  app.add_option("--encoder-noise-deg", args.encoder_noise_deg, "Std of the joint reading noise (deg)")
      ->check(CLI::Range(0.0, 10.0));
  AddFaultOption(app, "--reject-move", &args.reject, "Refuse move K");
  AddFaultOption(app, "--hang-move", &args.hang, "Move K freezes half way and never finishes");
  AddFaultOption(app, "--protective-stop-move", &args.protective_stop, "Protective stop half way through move K");
  AddFaultOption(app, "--emergency-stop-move", &args.emergency_stop, "Emergency stop half way through move K");
  AddFaultOption(app, "--drop-connection-move", &args.drop_connection,
                 "Lose the connection half way through move K; the socket is closed");
  AddFaultOption(app, "--jog-after-move", &args.jog_after, "Someone jogs the arm after move K settled");
  app.add_option("--jog-deg", args.jog_deg, "Size of that jog on joint 1 (deg; default 0.02 rad)");
  AddFaultOption(app, "--slow-settle-move", &args.slow_settle, "Move K rings down 20 times slower");
  AddFaultOption(app, "--never-settle-move", &args.never_settle,
                 "After move K every joint reads 0.05 rad/s: the arm never comes to rest");
  AddFaultOption(app, "--stale-read", &args.stale_read, "Joint reading N is stale");
  AddFaultOption(app, "--nan-read", &args.nan_read, "Joint reading N has NaN in joint 2");
  AddFaultOption(app, "--short-read", &args.short_read, "Joint reading N lacks a joint");
  if (const std::optional<int> exit_code = selfcal::app::ParseFakeCommandLine(app, argc, argv)) return *exit_code;

  const Result<RobotModel> model = io::LoadRobotModel(FindDataFile(args.robot));
  if (!model.ok()) return Fail(model.status());
  const int n = model->num_joints();

  robot::SimulatedRobotOptions options;
  options.identity.model = model->name;
  options.identity.serial = args.serial;
  options.identity.calibration_id = args.calibration_id;
  options.limits.lower_rad.resize(n);
  options.limits.upper_rad.resize(n);
  options.limits.max_velocity_rad_s = Eigen::VectorXd::Constant(n, args.max_velocity_deg_s * kRadPerDeg);
  options.initial_joints_rad.resize(n);
  for (int j = 0; j < n; ++j) {
    options.limits.lower_rad[j] = model->limits[j].min_rad;
    options.limits.upper_rad[j] = model->limits[j].max_rad;
    const bool zero_inside = model->limits[j].min_rad <= 0 && 0 <= model->limits[j].max_rad;
    options.initial_joints_rad[j] = zero_inside ? 0.0 : 0.5 * (model->limits[j].min_rad + model->limits[j].max_rad);
  }
  if (!args.initial_joints_deg.empty()) {
    if (static_cast<int>(args.initial_joints_deg.size()) != n) {
      return Fail(Status::Error(ErrorCode::kInvalidInput, "--initial-joints-deg: " + std::to_string(args.initial_joints_deg.size()) +
                                                      " values for " + std::to_string(n) + " joints"));
    }
    for (int j = 0; j < n; ++j) options.initial_joints_rad[j] = args.initial_joints_deg[j] * kRadPerDeg;
  }
  if (!args.start_at_plan.empty()) {
    const Result<io::TrajectoryFile> plan =
        io::LoadTrajectoryFileForRobot(FindDataFile(args.start_at_plan), *model, args.robot);
    if (!plan.ok()) return Fail(plan.status());
    if (plan->poses.empty()) {
      return Fail(Status::Error(ErrorCode::kInvalidInput, "--start-at-plan " + args.start_at_plan + ": no poses"));
    }
    options.initial_joints_rad = plan->poses.front();
  }
  options.latency_s = args.latency_s;
  options.encoder_noise_rad = args.encoder_noise_deg * kRadPerDeg;
  options.seed = args.seed;
  robot::SimulatedRobotFaults& faults = options.faults;
  faults.reject_moves = AsSet(args.reject);
  faults.hang_moves = AsSet(args.hang);
  faults.protective_stop_moves = AsSet(args.protective_stop);
  faults.emergency_stop_moves = AsSet(args.emergency_stop);
  faults.disconnect_moves = AsSet(args.drop_connection);
  faults.jog_after_moves = AsSet(args.jog_after);
  if (args.jog_deg != 0) {
    faults.jog_offset_rad = Eigen::VectorXd::Zero(n);
    faults.jog_offset_rad[0] = args.jog_deg * kRadPerDeg;
  }
  faults.slow_settle_moves = AsSet(args.slow_settle);
  faults.never_settle_moves = AsSet(args.never_settle);
  faults.stale_reads = AsSet(args.stale_read);
  faults.nan_reads = AsSet(args.nan_read);
  faults.short_reads = AsSet(args.short_read);
  if (const Status valid = options.Validate(); !valid.ok()) return Fail(valid);

  robot::MonotonicClock clock;
  robot::SimulatedRobot robot(options, clock);
  robot::RobotServerOptions server_options;
  server_options.port = args.port;
  server_options.log = &std::cerr;
  robot::RobotServer server(robot, server_options);
  if (const Status listening = server.Listen(); !listening.ok()) return Fail(listening);

  const std::atomic<bool>& stop = selfcal::app::StopOnSignals();

  std::cout << "listening on 127.0.0.1:" << server.port() << std::endl;
  const Status served = server.Serve(stop);
  const robot::CommandCounts& counts = robot.counts();
  std::cerr << "selfcal-robot-sim: stopped; moves accepted " << robot.accepted_moves().size() << " of "
            << counts.start_move << ", readings " << counts.read << ", stops " << counts.stop << "\n";
  return served.ok() ? 0 : Fail(served);
}

// selfcal-ur-fake: a loopback fake of a Universal Robots controller (robot/ur_fake.h): RTDE, the secondary
// interface and the Dashboard server on 127.0.0.1, with faults on request. For testing and rehearsing
// `selfcal run --backend ur` without an arm; not a simulator of a UR's motion or safety system
// (docs/universal-robots.md). Prints its three ports on the first line of stdout, then every line it
// receives; SIGINT and SIGTERM stop it (exit 0) after a last line with the motion and stop commands counted.
#include <atomic>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/exit_codes.h"
#include "app/fake_main.h"
#include "robot/ur_fake.h"

namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

}  // namespace

int main(int argc, char** argv) {
  using namespace selfcal;
  CLI::App app{"selfcal-ur-fake: a loopback fake of a Universal Robots controller (RTDE, secondary interface, "
               "Dashboard server) on 127.0.0.1"};
  robot::UrFakeOptions options;
  std::vector<double> start_deg;
  app.add_option("--rtde-port", options.rtde_port, "RTDE port (0: any free port; a controller's: 30004)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--secondary-port", options.secondary_port, "Secondary interface port (0: any; a controller's: 30002)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--dashboard-port", options.dashboard_port, "Dashboard server port (0: any; a controller's: 29999)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--model", options.model, "What get_robot_model answers");
  app.add_option("--serial", options.serial, "What get_serial_number answers");
  app.add_option("--start-deg", start_deg, "The six start joints (deg; default 0,-90,90,-90,-90,0)")
      ->delimiter(',')
      ->expected(6);
  app.add_option("--drop-move", options.drop_move, "Close every connection half way through move K (0-based)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--protective-stop-move", options.protective_stop_move, "Protective stop half way through move K")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--stall-move", options.stall_move, "Move K stops half way and never finishes")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--wrong-recipe", options.wrong_recipe, "Answer the RTDE recipe setup with NOT_FOUND for a variable");
  app.add_flag("--remote-control-off", options.remote_control_off,
               "The Dashboard says remote control is off (and scripts are ignored)");
  app.add_flag("--protective-stop-at-start", options.protective_stop_at_start, "Start in a protective stop");
  app.add_flag("--program-running", options.program_running, "A program runs on the controller (runtime_state 2)");
  if (const std::optional<int> exit_code = selfcal::app::ParseFakeCommandLine(app, argc, argv)) return *exit_code;
  for (size_t j = 0; j < start_deg.size(); ++j) options.start_rad[static_cast<int>(j)] = start_deg[j] * kRadPerDeg;
  Result<robot::UrFakeController> fake = robot::UrFakeController::Listen(options);
  if (!fake.ok()) {
    std::cerr << "selfcal-ur-fake: " << fake.status().ToString() << "\n";
    return static_cast<int>(selfcal::app::ExitCodeFor(fake.status().code()));
  }
  const std::atomic<bool>& stop = selfcal::app::StopOnSignals();
  const robot::UrFakeController::Ports ports = fake->ports();
  std::cout << "listening on 127.0.0.1 rtde " << ports.rtde << " secondary " << ports.secondary << " dashboard "
            << ports.dashboard << std::endl;
  fake.value().Serve(stop, [](const std::string& line) { std::cout << line << std::endl; });
  std::cout << "stopped; motion commands " << fake->motion_commands() << ", stop commands " << fake->stop_commands()
            << std::endl;
  return 0;
}

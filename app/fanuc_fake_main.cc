// selfcal-fanuc-fake: a loopback fake of a FANUC controller's Remote Motion Interface (robot/fanuc_fake.h)
// on 127.0.0.1, with faults on request. For testing and rehearsing `selfcal run --backend fanuc` without an
// arm; not a simulator of a FANUC's motion or safety system (docs/fanuc.md). Prints its connect port on
// the first line of stdout, then every packet it receives; SIGINT and SIGTERM stop it (exit 0) after a last
// line with the motion instructions and aborts counted; SIGUSR1 is ABORT ALL and RESET at the teach pendant
// (the RMI program ended, an alarm cleared, the servos on again).
#include <atomic>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/exit_codes.h"
#include "app/fake_main.h"
#include "robot/fanuc_fake.h"

namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

}  // namespace

int main(int argc, char** argv) {
  using namespace selfcal;
  CLI::App app{"selfcal-fanuc-fake: a loopback fake of a FANUC controller's Remote Motion Interface on 127.0.0.1"};
  robot::FanucFakeOptions options;
  std::vector<double> start_deg;
  app.add_option("--port", options.connect_port, "RMI connect port (0: any free port; a controller's: 16001)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--start-deg", start_deg, "The six start joints (deg; default 0,0,0,0,-90,0)")->delimiter(',')->expected(6);
  app.add_option("--drop-move", options.drop_move, "Close the session connection half way through move K (0-based)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--servo-off-move", options.servo_off_move,
                 "The servos off half way through move K (FRC_SystemFault, ServoReady 0)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--stall-move", options.stall_move, "Move K stops half way and never finishes")->check(CLI::NonNegativeNumber);
  app.add_option("--wrong-answer-move", options.wrong_answer_move,
                 "Half way through move K, answer FRC_ReadJointAngles as another command")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--servo-off-at-start", options.servo_off_at_start, "Start with the servos off (ServoReady 0)");
  app.add_flag("--teach-pendant-enabled", options.teach_pendant_enabled, "Start with the teach pendant enabled (TPMode 1)");
  if (const std::optional<int> exit_code = selfcal::app::ParseFakeCommandLine(app, argc, argv)) return *exit_code;
  for (size_t j = 0; j < start_deg.size(); ++j) options.start_rad[static_cast<int>(j)] = start_deg[j] * kRadPerDeg;
  Result<robot::FanucFakeController> fake = robot::FanucFakeController::Listen(options);
  if (!fake.ok()) {
    std::cerr << "selfcal-fanuc-fake: " << fake.status().ToString() << "\n";
    return static_cast<int>(selfcal::app::ExitCodeFor(fake.status().code()));
  }
  const std::atomic<bool>& stop = selfcal::app::StopOnSignals();
  const std::atomic<int>& pendant_resets = selfcal::app::CountAcknowledgements();
  std::cout << "listening on 127.0.0.1:" << fake->connect_port() << " (session port " << fake->session_port() << ")"
            << std::endl;
  fake.value().Serve(stop, [](const std::string& line) { std::cout << line << std::endl; }, &pendant_resets);
  std::cout << "stopped; motion commands " << fake->motion_commands() << ", stop commands " << fake->stop_commands()
            << std::endl;
  return 0;
}

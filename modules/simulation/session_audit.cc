#include "simulation/session_audit.h"

#include <nlohmann/json.hpp>

#include "base/json_lines.h"
#include "base/terminal_text.h"
#include "io/robot_config.h"
#include "session/samples.h"
#include "session/session_snapshot.h"
#include "session/setup_file.h"
#include "simulation/sim_run_settings.h"
#include "simulation/sim_session.h"

namespace selfcal::simulation {

namespace {

// The recorded session's run settings, refused unless its images are the simulated camera's (any robot).
Result<SimCellOptions> SimulatedRunOptions(const session::SessionSnapshot& snapshot, const std::string& path) {
  Result<std::string> text = snapshot.Input("run.json");
  if (!text.ok()) return text.status();
  const std::string name = path + "/inputs/run.json";
  Result<RunBackends> backends = ReadRunBackends(*text, name);
  if (!backends.ok()) return backends.status();
  if (!backends->rendered()) {  // the simulated camera with any robot: the joints it rendered are recorded
    return Status::InvalidInput(
        "session " + path + " was recorded with robot \"" + TerminalSafe(backends->robot) + "\" and camera \"" +
        TerminalSafe(backends->camera) + "\" (" + backends->robot_at +
        "): only a session recorded with the simulated camera (run --camera sim, with the simulated "
        "robot or any other) has a hidden truth to audit against");
  }
  return SimCellOptionsFor(*text, name);
}

// A JSON value as a refusal quotes it: terminal-safe, at most 60 characters.
std::string Quoted(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return TerminalSafe(text);
}

// The recorded setup.json against the rebuilt world's: read as every reader of it does (a syntax error, a
// repeated key, a missing or mistyped one refused by line), then compared as data, so that the same setup
// written otherwise is the same setup; the first value that differs is refused naming its line and key.
Status CompareSetup(const std::string& rebuilt, const std::string& recorded, const std::string& path) {
  const std::string name = path + "/inputs/" + session::kSetupFileName;
  ObservationSet parsed;
  session::SetupNaming naming;
  if (Status s = session::ParseSetupFile(recorded, name, &parsed, &naming); !s.ok()) return s;
  const nlohmann::json expected = nlohmann::json::parse(rebuilt);
  const nlohmann::json found = nlohmann::json::parse(recorded);
  const nlohmann::json patch = nlohmann::json::diff(found, expected);  // what turns the recorded into the rebuilt
  if (patch.empty()) return Status::Ok();
  const nlohmann::json& first = patch.front();
  const std::string pointer = first.at("path").get<std::string>();
  const std::string op = first.at("op").get<std::string>();
  const std::string key = "`" + TerminalSafe(JsonPointerName(pointer)) + "`";
  const std::string world = "the simulated world rebuilt from robot.yaml, the journal's plan and run.json";
  std::string what;
  if (op == "replace") {
    what = key + " is " + Quoted(found.at(nlohmann::json::json_pointer(pointer))) + " where " + world + " has " +
           Quoted(first.at("value"));
  } else if (op == "remove") {
    what = key + " is not in the setup of " + world;
  } else {
    what = "missing " + key + ", which " + world + " has (" + Quoted(first.value("value", nlohmann::json())) + ")";
  }
  return Status::InvalidInput(
      name + ":" + std::to_string(JsonLines(recorded).Line(pointer)) + ": " + what +
      ": the world does not reproduce the recorded setup (recorded by another version?); its identities "
      "cannot be scored");
}

// The world `selfcal run` built for this session, rebuilt from its inputs and checked against setup.json.
Result<SimCell> RebuildWorld(const session::SessionSnapshot& snapshot, const session::SessionLog& log,
                             const SimCellOptions& options, const std::string& path) {
  Result<std::string> robot_text = snapshot.Input("robot.yaml");
  if (!robot_text.ok()) return robot_text.status();
  Result<RobotModel> nominal = io::ParseRobotModelText(*robot_text, path + "/inputs/robot.yaml");
  if (!nominal.ok()) return nominal.status();
  if (!log.plan_complete() || log.plan.empty()) {
    return Status::InvalidInput("session " + path + ": the journal holds " + std::to_string(log.plan.size()) + " of " +
                                std::to_string(log.num_poses) +
                                " planned poses; the world cannot be rebuilt without the plan");
  }
  Result<std::string> setup = snapshot.Input(session::kSetupFileName);
  if (!setup.ok()) return setup.status();
  ObservationSet recorded;  // the configuration and fixed camera of the cell (setup.json)
  if (Status s = session::ParseSetupFile(*setup, path + "/inputs/" + session::kSetupFileName, &recorded); !s.ok()) {
    return s;
  }
  RobotModel robot = *nominal;
  robot.mount = recorded.robot.mount;
  robot.base_from_cam = recorded.robot.base_from_cam;
  Result<SimCell> cell = MakeSimCell(robot, log.plan, options, log.plan.front().joints_rad, 0);
  if (!cell.ok()) return cell.status();
  if (Status s = CompareSetup(session::SetupFileText(SimSetup(*cell)), *setup, path); !s.ok()) return s;
  return cell;
}

}  // namespace

Result<IdentityAudit> AuditRecordedIdentities(const sim::SimResult& world, const std::string& session_path,
                                              const IdentityAuditOptions& options) {
  Result<session::SessionSnapshot> snapshot = session::ReadSession(session_path);
  if (!snapshot.ok()) return snapshot.status();
  Result<session::SessionLog> log = session::ReadSessionLog(snapshot->records);
  if (!log.ok()) return log.status();
  return AuditIdentities(world, *log, options);
}

Result<SessionAudit> AuditSession(const std::string& session_path, const IdentityAuditOptions& options) {
  Result<session::SessionSnapshot> snapshot = session::ReadSession(session_path);
  if (!snapshot.ok()) return snapshot.status();
  Result<SimCellOptions> cell_options = SimulatedRunOptions(*snapshot, session_path);
  if (!cell_options.ok()) return cell_options.status();
  Result<session::SessionLog> log = session::ReadSessionLog(snapshot->records);
  if (!log.ok()) return log.status();
  Result<SimCell> cell = RebuildWorld(*snapshot, *log, *cell_options, session_path);
  if (!cell.ok()) return cell.status();
  SessionAudit audit;
  audit.session_path = session_path;
  audit.robot_name = cell->world->truth.nominal.name;
  audit.seed = cell_options->world.world_seed;
  audit.identities = AuditIdentities(*cell->world, *log, options);
  return audit;
}

}  // namespace selfcal::simulation

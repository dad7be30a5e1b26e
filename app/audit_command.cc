// selfcal audit SESSION: the dot identities of a session recorded with the simulated camera (any robot),
// scored against the simulator's hidden truth (simulation/session_audit.h). Reads the session only.
#include <iomanip>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "app/cli_util.h"
#include "app/output_options.h"
#include "app/commands.h"
#include "io/report_json.h"
#include "simulation/session_audit.h"

namespace selfcal::app {

namespace {

struct AuditArgs {
  std::string session;
  std::string json;
  double gate_px = simulation::IdentityAuditOptions().gate_px;
};

void PrintAudit(const simulation::SessionAudit& audit, std::ostream& out) {
  const simulation::IdentityAudit& a = audit.identities;
  out << "session " << audit.session_path << ": simulated " << audit.robot_name << ", seed " << audit.seed
      << "; dot identities against the simulator's truth\n";
  out << "  pose   in view  named  named in view  wrong  right within px\n";
  for (const simulation::SampleIdentities& s : a.samples) {
    out << "  " << s.pose_id << std::string(s.pose_id.size() < 6 ? 6 - s.pose_id.size() : 1, ' ') << std::setw(8)
        << s.in_view << std::setw(7) << s.named << std::setw(15) << s.named_in_view << std::setw(7) << s.wrong
        << std::setw(16) << std::fixed << std::setprecision(3) << s.max_right_error_px << "\n";
  }
  out.unsetf(std::ios::floatfield);
  out << simulation::IdentityAuditSummary(a) << "\n";
  if (a.worst) {
    const simulation::WrongIdentity& w = *a.worst;
    out << "worst wrong identity: pose " << w.pose_id << ", named dot " << w.id << " at (" << w.pixel_px.x() << ", "
        << w.pixel_px.y() << ") px, " << w.own_distance_px << " px from that dot's true projection; it was dot "
        << w.true_id << " (" << w.true_distance_px << " px)\n";
  }
}

int Audit(const AuditArgs& args) {
  simulation::IdentityAuditOptions options;
  options.gate_px = args.gate_px;
  Result<simulation::SessionAudit> audit = simulation::AuditSession(args.session, options);
  if (!audit.ok()) return Fail(audit.status());
  PrintAudit(*audit, std::cout);
  if (!args.json.empty()) {
    nlohmann::json document = {{"format", "selfcal-identity-audit"},
                               {"version", 1},
                               {"session", audit->session_path},
                               {"robot", audit->robot_name},
                               {"seed", audit->seed},
                               {"identities", simulation::IdentityAuditJson(audit->identities)}};
    if (Status s = io::WriteJsonFile(document, args.json); !s.ok()) return Fail(s);
    std::cout << "wrote " << args.json << "\n";
  }
  return 0;
}

}  // namespace

Command AddAuditCommand(CLI::App& app) {
  auto args = std::make_shared<AuditArgs>();
  CLI::App* cmd = app.add_subcommand(
      "audit", "Score a simulated session's dot identities against the simulator's hidden truth (reads only)");
  cmd->add_option("session", args->session, "Session directory recorded with --camera sim (--backend sim or any other robot)")->required();
  AddOutputOption(cmd, "--json", &args->json, OutputKind::kFile, "Write the audit as JSON to this file (outside the session)");
  cmd->add_option("--gate-px", args->gate_px, "A name farther than this from its dot's true projection is wrong")
      ->check(CLI::Range(0.1, 50.0));
  return [args]() { return Audit(*args); };
}

}  // namespace selfcal::app

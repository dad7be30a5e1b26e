// selfcal session discard DIR: removes a session directory that recorded nothing (an interrupted creation,
// or a session without any frame or sample); refuses a recorded one (session/session_cleanup.h).
#include <iostream>
#include <memory>
#include <string>

#include "app/cli_util.h"
#include "app/commands.h"
#include "session/session_cleanup.h"

namespace selfcal::app {

Command AddSessionCommand(CLI::App& app) {
  auto dir = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("session", "Manage session directories (docs/session-format.md)");
  cmd->require_subcommand(1);
  CLI::App* discard = cmd->add_subcommand(
      "discard", "Remove a session directory that holds no recorded frame or sample (an interrupted creation)");
  discard->add_option("DIR", *dir, "Session directory")->required();
  return [dir]() {
    Result<session::SessionDirInspection> found = session::InspectSessionDir(*dir);
    if (Status s = session::DiscardSession(*dir, /*take_over_stale_lock=*/true); !s.ok()) return Fail(s);
    std::cout << "removed " << *dir << " (" << session::SessionDirStateName(found->state) << ": "
              << found->journal_records << " journal records, no frame or sample)\n";
    return 0;
  };
}

}  // namespace selfcal::app

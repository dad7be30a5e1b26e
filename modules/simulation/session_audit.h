// `selfcal audit SESSION`: the dot identities of a session recorded with the simulated camera (any robot),
// scored against the simulator's hidden truth (identity_audit.h). Read-only: the session is read through
// session::ReadSession (no lock, nothing written). The hidden world is not stored in the session; it is
// rebuilt from the recorded inputs exactly as `selfcal run` built it (robot.yaml, the journal's plan,
// run.json through SimCellOptionsFor, MakeSimCell), and the rebuilt world must reproduce the recorded
// setup.json byte for byte (yardstick, check distances and camera all follow from the hidden world), or
// the audit is refused.
#pragma once

#include <cstdint>
#include <string>

#include "base/status.h"
#include "sim/sim_world.h"
#include "simulation/identity_audit.h"

namespace selfcal::simulation {

struct SessionAudit {
  std::string session_path;
  std::string robot_name;  // the nominal model's name
  uint64_t seed = 0;       // run.json "seed"
  IdentityAudit identities;
};

// The audit of the session at `session_path`. kInvalidInput naming the session and file when it cannot
// be read, was not recorded with the simulated camera (run.json), or its world cannot be
// rebuilt identically; kDegenerateData when the world cannot be simulated at all.
Result<SessionAudit> AuditSession(const std::string& session_path,
                                  const IdentityAuditOptions& options = IdentityAuditOptions());

// The identities of the session at `session_path` scored against `world`, the world it ran in (`selfcal
// simulate` holds it): reads the journal only.
Result<IdentityAudit> AuditRecordedIdentities(const sim::SimResult& world, const std::string& session_path,
                                              const IdentityAuditOptions& options = IdentityAuditOptions());

}  // namespace selfcal::simulation

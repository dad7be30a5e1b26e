// The simulated cell of a session from its run.json (docs/session-format.md): the one mapping from the
// recorded run settings (seed, rendering, simulated faults) to SimCellOptions, shared by `selfcal run`
// (which writes run.json and builds the cell from it) and by readers that rebuild the identical world
// offline (`selfcal audit`, identity_audit.h). Whatever builds a simulated session's cell goes through
// here, so that a recorded session's world can be rebuilt bit for bit from its inputs.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "base/status.h"
#include "simulation/sim_session.h"

namespace selfcal::simulation {

// The cell options of a session recorded with these run settings (run.json: "seed", "grey_noise",
// "blur_px", "supersampling", "faults": {"reject_moves", ...}). World and noise seed = "seed"; the
// solvers are told a centroid noise of 0.02 px (measured 0.01 px at grey noise 2). kInvalidInput naming
// `name` and the key for a missing or mistyped key.
Result<SimCellOptions> SimCellOptionsFor(const nlohmann::json& run_json, const std::string& name = "run.json");

// True when run.json records the simulated robot and camera ("robot": "sim", "camera": "sim").
bool IsSimulatedRun(const nlohmann::json& run_json);

}  // namespace selfcal::simulation

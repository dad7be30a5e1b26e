// The simulated cell of a session from its run.json (docs/session-format.md): the one mapping from the
// recorded run settings (seed, rendering, simulated faults) to SimCellOptions, shared by `selfcal run`
// (which writes run.json and builds the cell from it) and by readers that rebuild the identical world
// offline (`selfcal audit`, identity_audit.h). Whatever builds a simulated session's cell goes through
// here, so that a recorded session's world can be rebuilt bit for bit from its inputs.
//
// Both readers take run.json's text and refuse with kInvalidInput naming the file and line
// ("<file>:<line>: `faults.nan_reads` must be an array (found string)", session/json_fields.h): text
// that is not JSON, not an object, a key given twice, a missing or mistyped key, a value out of the range
// `selfcal run` accepts, an unknown key. Both check every key docs/session-format.md lists for run.json:
// "format" "selfcal-run", "version" 1, "robot" sim|network|manual, "camera" sim|v4l2, "address" and
// "device" strings, "velocity_scaling" in [0.001, 1], and the cell's settings below.
#pragma once

#include <string>

#include "base/status.h"
#include "simulation/sim_session.h"

namespace selfcal::simulation {

// The cell options of a session recorded with these run settings (run.json: "seed", "grey_noise" in
// [0, 50], "blur_px" in [0, 10], "supersampling" in [1, 8], "faults": {"reject_moves": [k, ...], ...,
// optional "jog_delay_s" in [0, 10]}, each fault list of 0-based call counts). World and noise seed =
// "seed"; the solvers are told a centroid noise of 0.02 px (measured 0.01 px at grey noise 2).
Result<SimCellOptions> SimCellOptionsFor(const std::string& run_json_text, const std::string& name = "run.json");

// The backends a run.json records ("robot", "camera"), and where "robot" is ("<file>:<line>").
struct RunBackends {
  std::string robot;
  std::string camera;
  std::string robot_at;

  // The simulated robot and camera ("robot": "sim", "camera": "sim").
  bool simulated() const { return robot == "sim" && camera == "sim"; }
  // Images of the simulated cell ("camera": "sim", any robot: the camera renders the joints the robot
  // reports): a session with a hidden truth.
  bool rendered() const { return camera == "sim"; }
};
Result<RunBackends> ReadRunBackends(const std::string& run_json_text, const std::string& name = "run.json");

}  // namespace selfcal::simulation

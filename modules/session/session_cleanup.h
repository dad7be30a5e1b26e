// What a directory named as a session holds, and removing one that holds nothing recorded
// (docs/session-format.md, "Interrupted creation"): a creation cut short (no session.json) or a session
// that recorded no frame can be completed by `selfcal run --resume` or removed by `selfcal session
// discard`, never by hand. Recorded data is never removed (../shared/RELIABILITY.md: recorded session data is never
// deleted by an error path, nor by this command).
#pragma once

#include <string>
#include <vector>

#include "base/status.h"
#include "session/session_dir.h"

namespace selfcal::session {

enum class SessionDirState {
  kAbsent,               // nothing at the path
  kEmpty,                // an empty directory
  kInterruptedCreation,  // the layout of a session (lock, inputs/, images/, journal.log) but no session.json
  kNothingRecorded,      // session.json, and no frame_written or sample_accepted record, no image
  kRecorded,             // at least one frame, sample or image: recorded data
};
const char* SessionDirStateName(SessionDirState state);

struct SessionDirInspection {
  SessionDirState state = SessionDirState::kAbsent;
  int journal_records = 0;                   // durable records (a torn tail not counted)
  int frames = 0, samples = 0, images = 0;   // frame_written, sample_accepted; files in images/ + orphans/
  std::vector<std::string> foreign;          // entries selfcal does not write into a session directory
  std::vector<SessionInput> recorded_inputs; // kInterruptedCreation: the inputs/ copies written so far
};

// Looks at `path` without changing anything (no lock taken). kInvalidInput when the path is not a
// directory, or its journal is damaged (a torn tail is not damage); the temporary files of interrupted
// atomic writes (".<name>.tmp.XXXXXX") are neither images nor inputs.
Result<SessionDirInspection> InspectSessionDir(const std::string& path);

// The inputs an interrupted creation wrote that differ from `expected` (by name; an input not written yet
// does not differ), as "<name>" lines for a refusal.
std::vector<std::string> DifferingInputs(const SessionDirInspection& inspection, const SessionInputs& expected);

// Removes the session directory `path` when it holds nothing recorded (kEmpty, kInterruptedCreation,
// kNothingRecorded) and nothing selfcal did not write: takes the lock first (refused while another process
// holds it), then removes the known entries and the directory. Refused with kInvalidInput, changing
// nothing, for a recorded session ("holds N recorded samples ..."), foreign entries (named) or a damaged
// journal; kInvalidInput for a missing path. A stale lock (its holder died) is taken over only with
// `take_over_stale_lock` (session_lock.h); `selfcal session discard` passes true: the command is the
// operator's confirmation.
Status DiscardSession(const std::string& path, bool take_over_stale_lock);

}  // namespace selfcal::session

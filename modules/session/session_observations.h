// The observations of a recorded session for an offline calibration (`selfcal calibrate SESSION`), read
// through the read-only snapshot (session_snapshot.h): nothing on disk changes.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "base/status.h"
#include "observations/observation_set.h"
#include "session/journal.h"

namespace selfcal::session {

// The journal's counts, for the report of a calibration.
struct JournalSummary {
  std::string session_id;
  int poses_planned = 0;
  int samples_accepted = 0;
  int resumes = 0;
  bool finished = false;  // a finished record after the last start or resume
  std::map<std::string, int> skips_by_reason;
  std::map<std::string, int> faults_by_kind;
  std::map<std::string, int> halts_by_reason;
  int rejected_frames = 0;  // frame_rejected records: frames of skipped poses in images/rejected/, not used
};

struct SessionObservations {
  ObservationSet observations;  // setup.json + robot.yaml + the accepted samples in plan order
  JournalSummary summary;
  std::string manifest_sha256;  // SHA-256 of session.json: the provenance of a model calibrated from it
  JournalRecovery torn_tail;    // torn_tail.truncated(): what a resume would truncate (left in place)
  std::vector<std::string> unrecorded_images;  // "images/<name>" a resume would move to orphans/ (left)
  std::vector<std::string> findings;           // SessionSnapshot::Findings(): one warning line per item above
};

// Builds the ObservationSet of the session at `session_path` from ReadSession (every recorded input
// checked against its size and SHA-256; nothing locked or changed): the setup.json input (camera,
// yardsticks, checks), the robot.yaml input and the accepted samples of the journal in plan order, after
// checking every sample's image against its frame_written record (P2). kInvalidInput naming the session, file
// or record on any inconsistency; kDegenerateData when fewer than two identification samples were
// accepted or the set is invalid.
Result<SessionObservations> LoadSessionObservations(const std::string& session_path);

}  // namespace selfcal::session

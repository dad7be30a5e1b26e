// A read-only view of a recorded session for offline readers (`selfcal calibrate SESSION`): the session
// owns its data, and reading it for a calibration changes nothing on disk (docs/session-format.md,
// "Reading a session offline"). Unlike OpenSession (session_dir.h), ReadSession takes no lock, creates,
// truncates, renames and writes nothing; what a resume would repair is reported instead of done.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/status.h"
#include "session/journal.h"
#include "session/session_dir.h"

namespace selfcal::session {

struct SessionSnapshot {
  std::string path;
  SessionManifest manifest;
  std::string manifest_sha256;  // SHA-256 of session.json as read: the provenance of a result made from it
  // Every input the manifest records, by name: the bytes of inputs/<name>, checked against the recorded
  // size and SHA-256.
  std::map<std::string, std::string> inputs;
  std::vector<nlohmann::json> records;  // the valid journal records, in file order
  // journal.truncated(): a torn tail of journal.dropped_bytes bytes at byte offset journal.valid_bytes,
  // which a resume would truncate; left in place here.
  JournalRecovery journal;
  // Files of images/ no record names ("images/<name>"), which a resume would move to orphans/; left in place.
  std::vector<std::string> unrecorded_images;

  // The checked bytes of input `name`; kInvalidInput naming the session when the manifest does not record it.
  Result<std::string> Input(const std::string& name) const;
  // One line per finding above, each saying what a resume would do and that nothing was changed; empty
  // when the session is clean.
  std::vector<std::string> Findings() const;
};

// Reads the session at `path` without changing anything, in this order:
//  1. session.json, strictly (as ReadManifest); images/ and journal.log must exist;
//  2. every input the manifest records, against its recorded size and SHA-256: a missing or differing
//     one is refused (kInvalidInput listing every such file, e.g. "<path>/inputs/robot.yaml: differs from the
//     size or SHA-256 recorded in session.json (...)");
//  3. the journal, read-only (ReadJournal): damage is refused, a torn tail reported;
//  4. the unrecorded images, listed.
Result<SessionSnapshot> ReadSession(const std::string& path, const JournalLimits& journal_limits = JournalLimits());

}  // namespace selfcal::session

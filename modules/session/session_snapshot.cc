#include "session/session_snapshot.h"

#include "session/file_util.h"

namespace selfcal::session {

Result<std::string> SessionSnapshot::Input(const std::string& name) const {
  const auto it = inputs.find(name);
  if (it == inputs.end()) {
    return Status::Error(ErrorCode::kInvalidInput, "session " + path + " has no input \"" + name + "\" in " +
                                               kManifestFileName);
  }
  return it->second;
}

std::vector<std::string> SessionSnapshot::Findings() const {
  std::vector<std::string> findings;
  const std::string journal_file = internal::Join(path, kJournalFileName);
  if (journal.truncated()) {
    findings.push_back(journal_file + " ends in a torn tail of " + std::to_string(journal.dropped_bytes) +
                       " bytes at byte offset " + std::to_string(journal.valid_bytes) + " (" + journal.reason +
                       "): it would be truncated on resume; left unchanged");
  }
  for (const std::string& image : unrecorded_images) {
    findings.push_back(internal::Join(path, image) + " is named by no journal record: it would be moved to " +
                       kOrphansDirName + "/ on resume; left unchanged");
  }
  return findings;
}

Result<SessionSnapshot> ReadSession(const std::string& path, const JournalLimits& journal_limits) {
  SessionSnapshot snapshot;
  snapshot.path = path;
  Result<SessionManifest> manifest = ReadManifest(path, &snapshot.manifest_sha256);
  if (!manifest.ok()) return manifest.status();
  snapshot.manifest = std::move(manifest).value();
  if (Status s = CheckSessionLayout(path); !s.ok()) return s;

  std::vector<std::string> problems;
  for (const InputDigest& digest : snapshot.manifest.inputs) {
    Result<std::string> bytes = ReadRecordedInput(path, digest);
    if (bytes.ok()) {
      snapshot.inputs.emplace(digest.name, std::move(bytes).value());
    } else {
      problems.push_back(bytes.status().message());
    }
  }
  if (!problems.empty()) {
    std::string message;
    for (const std::string& problem : problems) message += (message.empty() ? "" : "; ") + problem;
    return Status::Error(ErrorCode::kInvalidInput, message + "; refusing to read session " + path);
  }

  Result<JournalContents> journal = ReadJournal(internal::Join(path, kJournalFileName), journal_limits);
  if (!journal.ok()) return journal.status();
  snapshot.records = std::move(journal->records);
  snapshot.journal = journal->recovery;
  Result<std::vector<std::string>> unrecorded = UnrecordedImages(path, snapshot.records);
  if (!unrecorded.ok()) return unrecorded.status();
  for (const std::string& name : *unrecorded) snapshot.unrecorded_images.push_back(ImageRecordPath(name));
  return snapshot;
}

}  // namespace selfcal::session

#include "session/session_cleanup.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <set>

#include "base/atomic_file.h"
#include "session/file_util.h"
#include "session/journal.h"
#include "session/session_lock.h"

namespace selfcal::session {

namespace {

namespace fs = std::filesystem;
using internal::Join;
using internal::SystemError;

// ".<name>.tmp.XXXXXX": a temporary file of base/atomic_file.h, left by a write cut short.
bool IsAtomicTemporary(const std::string& name) {
  return name.size() > 1 && name[0] == '.' && name.find(".tmp.") != std::string::npos;
}

// The entries of `directory`, sorted; kInvalidInput naming it when it cannot be listed.
Result<std::vector<fs::directory_entry>> Entries(const std::string& directory) {
  std::error_code error;
  std::vector<fs::directory_entry> entries;
  for (fs::directory_iterator it(directory, error), end; !error && it != end; it.increment(error)) {
    entries.push_back(*it);
  }
  if (error) return Status::InvalidInput("cannot list " + directory + ": " + error.message());
  std::sort(entries.begin(), entries.end());
  return entries;
}

// Files in images/ (and its rejected/) or orphans/ (not the temporaries of an interrupted write); other
// directories there are foreign.
Status CountImages(const std::string& directory, SessionDirInspection* out, bool with_rejected = false) {
  if (!fs::is_directory(fs::symlink_status(directory))) return Status::Ok();
  Result<std::vector<fs::directory_entry>> entries = Entries(directory);
  if (!entries.ok()) return entries.status();
  for (const fs::directory_entry& e : *entries) {
    const std::string name = e.path().filename().string();
    if (with_rejected && name == kRejectedDirName && fs::is_directory(e.symlink_status())) {
      if (Status s = CountImages(e.path().string(), out); !s.ok()) return s;
    } else if (fs::is_directory(e.symlink_status())) {
      out->foreign.push_back(e.path().string());
    } else if (!IsAtomicTemporary(name)) {
      ++out->images;
    }
  }
  return Status::Ok();
}

// The copies in inputs/ (temporaries skipped); subdirectories there are foreign.
Status ReadRecordedInputs(const std::string& directory, SessionDirInspection* out) {
  if (!fs::is_directory(fs::symlink_status(directory))) return Status::Ok();
  Result<std::vector<fs::directory_entry>> entries = Entries(directory);
  if (!entries.ok()) return entries.status();
  for (const fs::directory_entry& e : *entries) {
    const std::string name = e.path().filename().string();
    if (!fs::is_regular_file(e.symlink_status())) {
      out->foreign.push_back(e.path().string());
      continue;
    }
    if (IsAtomicTemporary(name)) continue;
    Result<SessionInput> input = ReadInputFile(name, e.path().string());
    if (!input.ok()) return input.status();
    out->recorded_inputs.push_back(std::move(input).value());
  }
  return Status::Ok();
}

}  // namespace

const char* SessionDirStateName(SessionDirState state) {
  switch (state) {
    case SessionDirState::kAbsent: return "absent";
    case SessionDirState::kEmpty: return "empty";
    case SessionDirState::kInterruptedCreation: return "interrupted creation";
    case SessionDirState::kNothingRecorded: return "nothing recorded";
    case SessionDirState::kRecorded: return "recorded";
  }
  return "unknown";
}

Result<SessionDirInspection> InspectSessionDir(const std::string& path) {
  SessionDirInspection out;
  std::error_code error;
  const fs::file_status status = fs::symlink_status(path, error);
  if (!fs::exists(status)) return out;
  if (!fs::is_directory(status)) return Status::InvalidInput(path + " exists and is not a directory");
  Result<std::vector<fs::directory_entry>> entries = Entries(path);
  if (!entries.ok()) return entries.status();
  if (entries->empty()) {
    out.state = SessionDirState::kEmpty;
    return out;
  }
  static const std::set<std::string> kKnown = {kManifestFileName, kLockFileName, kJournalFileName,
                                               kInputsDirName,    kImagesDirName, kOrphansDirName};
  bool has_manifest = false;
  for (const fs::directory_entry& e : *entries) {
    const std::string name = e.path().filename().string();
    has_manifest = has_manifest || name == kManifestFileName;
    if (kKnown.count(name) == 0 && !IsAtomicTemporary(name)) out.foreign.push_back(e.path().string());
  }
  for (const char* dir : {kImagesDirName, kOrphansDirName}) {
    if (Status s = CountImages(Join(path, dir), &out, std::string(dir) == kImagesDirName); !s.ok()) return s;
  }
  const std::string journal = Join(path, kJournalFileName);
  if (fs::exists(fs::symlink_status(journal))) {
    Result<JournalContents> contents = ReadJournal(journal);
    if (!contents.ok()) return contents.status();
    out.journal_records = static_cast<int>(contents->records.size());
    for (const nlohmann::json& record : contents->records) {
      const std::string type = record.value("type", "");
      out.frames += type == "frame_written" ? 1 : 0;
      out.samples += type == "sample_accepted" ? 1 : 0;
    }
  }
  if (out.frames > 0 || out.samples > 0 || out.images > 0) {
    out.state = SessionDirState::kRecorded;
  } else if (has_manifest) {
    out.state = SessionDirState::kNothingRecorded;
  } else {
    out.state = SessionDirState::kInterruptedCreation;
    if (Status s = ReadRecordedInputs(Join(path, kInputsDirName), &out); !s.ok()) return s;
  }
  return out;
}

std::vector<std::string> DifferingInputs(const SessionDirInspection& inspection, const SessionInputs& expected) {
  std::vector<std::string> differing;
  for (const SessionInput& recorded : inspection.recorded_inputs) {
    bool same = false, known = false;
    for (const SessionInput& e : expected) {
      if (e.name != recorded.name) continue;
      known = true;
      same = e.contents == recorded.contents;
    }
    if (!same) differing.push_back(recorded.name + (known ? "" : " (not an input of this run)"));
  }
  return differing;
}

Status DiscardSession(const std::string& path, bool take_over_stale_lock) {
  Result<SessionDirInspection> inspection = InspectSessionDir(path);
  if (!inspection.ok())
    return Status::InvalidInput("cannot discard session " + path + ": " + inspection.status().message());
  const SessionDirInspection& in = *inspection;
  if (in.state == SessionDirState::kAbsent)
    return Status::InvalidInput("cannot discard session " + path + ": no such directory");
  if (in.state == SessionDirState::kRecorded) {
    return Status::InvalidInput("session " + path + " holds recorded data (" + std::to_string(in.samples) +
                                " accepted samples, " + std::to_string(in.frames) + " frames, " +
                                std::to_string(in.images) +
                                " image files): recorded data is never removed; resume it, or calibrate from it");
  }
  if (!in.foreign.empty()) {
    std::string list;
    for (const std::string& f : in.foreign) list += (list.empty() ? "" : ", ") + f;
    return Status::InvalidInput("cannot discard session " + path + ": it holds entries selfcal did not write (" + list +
                                "); nothing was removed");
  }
  // The lock first: a process still creating or running this session keeps it.
  Result<SessionLock> lock = SessionLock::Acquire(path, false, take_over_stale_lock);
  if (!lock.ok()) return Status::InvalidInput("cannot discard session " + path + ": " + lock.status().message());
  Result<std::vector<fs::directory_entry>> entries = Entries(path);
  if (!entries.ok()) return entries.status();
  for (const fs::directory_entry& e : *entries) {
    if (e.path().filename() == kLockFileName) continue;
    std::error_code error;
    fs::remove_all(e.path(), error);
    if (error) return Status::InvalidInput("cannot remove " + e.path().string() + ": " + error.message());
  }
  const std::string lock_file = Join(path, kLockFileName);
  if (::unlink(lock_file.c_str()) != 0 && errno != ENOENT) return SystemError("cannot remove", lock_file, errno);
  lock.value().Release();
  if (::rmdir(path.c_str()) != 0) return SystemError("cannot remove directory", path, errno);
  fs::path normal = fs::path(path).lexically_normal();
  if (!normal.has_filename()) normal = normal.parent_path();  // "a/b/" names b
  const std::string parent = normal.parent_path().string();
  if (!FsyncDirectory(parent.empty() ? "." : parent)) return SystemError("cannot fsync directory", parent, errno);
  return Status::Ok();
}

}  // namespace selfcal::session

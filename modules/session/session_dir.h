// Module session (ARCHITECTURE.md): session directories (this header, docs/session-format.md):
// journal.h (append-only, length + CRC framing, fdatasync per record, torn-tail recovery, refusal of damage),
// session_lock.h (flock with stale-lock takeover), samples.h (record types and ReadSessionLog: plan, accepted
// samples, skips, counts, resume point), planned_pose.h (the plan's pose, also the session loop's),
// session_snapshot.h (the read-only ReadSession of offline readers and `run --resume --dry-run`: no lock,
// nothing written, every input checked against its SHA-256), session_observations.h
// (LoadSessionObservations), setup_file.h (setup.json), json_fields.h (file:line refusals through
// base/json_lines.h), output_path.h (CheckOutputPath: the one rule of every command's output paths, never
// inside a session, never over an input, never over an existing file without --force, a place that can be
// written). Rejected frames of skipped poses live in images/rejected/, journaled as frame_rejected; readers
// never use them. Uses base, observations; io private (the robot config).
//
// A calibration session directory (docs/session-format.md; ../shared/RELIABILITY.md P1-P6, C9, C10): the durable,
// resumable record of one session, from which `selfcal calibrate SESSION` solves offline and
// `selfcal run --resume SESSION` continues after a crash.
//
//   <session>/session.json   manifest: format, version, session id, creation time, software version,
//                            configuration (eye_in_hand, eye_to_hand), inputs with size and SHA-256 (written last at creation: the commit point)
//   <session>/lock           advisory lock, "<pid> <host> <start time>" of the holder (session_lock.h)
//   <session>/journal.log    append-only journal of every event (journal.h; record types: samples.h)
//   <session>/inputs/<name>  read-only (0444) copies of the config, robot, plan and camera files
//   <session>/images/<name>  one file per grabbed frame, each written atomically before its journal record
//   <session>/images/rejected/<name>  the frames of skipped poses (kept for the operator, never observations)
//   <session>/orphans/<name> images no durable journal record names, moved aside on open (never deleted)
//
// Write order of a frame (P1): WriteImage (temporary file -> fsync -> link to images/<name> -> directory
// fsync), then journal().Append of the record naming "images/<name>" (write + fdatasync). A frame counts
// only once its record is durable; an image without one becomes an orphan on the next open (P2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "base/status.h"
#include "kinematics/robot_model.h"
#include "session/journal.h"
#include "session/session_lock.h"

namespace selfcal::session {

inline constexpr const char* kSessionFormatName = "selfcal-session";
inline constexpr int kSessionFormatVersion = 1;
inline constexpr const char* kManifestFileName = "session.json";
inline constexpr const char* kInputsDirName = "inputs";
inline constexpr const char* kImagesDirName = "images";
inline constexpr const char* kOrphansDirName = "orphans";
inline constexpr const char* kRejectedDirName = "rejected";  // images/rejected/: frames of skipped poses
inline constexpr std::size_t kMaxInputBytes = std::size_t{64} << 20;  // per input file

// One input file of a session, e.g. {"config.yaml", <its bytes>}.
struct SessionInput {
  std::string name;  // plain file name (no '/', not hidden)
  std::string contents;
};
using SessionInputs = std::vector<SessionInput>;  // in the order they are recorded

// Input `name` with the bytes of the file `path` (at most kMaxInputBytes), for CreateSession and
// OpenSession. kInvalidInput naming the path when it is missing, unreadable, not a regular file or too large.
Result<SessionInput> ReadInputFile(const std::string& name, const std::string& path);

struct InputDigest {
  std::string name;
  std::uint64_t bytes = 0;
  std::string sha256_hex;  // 64 lower-case hex digits
};

// session.json.
struct SessionManifest {
  int version = kSessionFormatVersion;
  std::string session_id;
  std::string created_utc;  // UTC ISO 8601, e.g. "2025-03-01T12:00:00Z"
  std::string software_version;
  // Where the camera is (kinematics/robot_model.h): "configuration" in session.json, eye_in_hand when a
  // session recorded before the key has none. A resume in the other configuration is refused.
  CameraMount configuration = CameraMount::kEyeInHand;
  std::vector<InputDigest> inputs;

  const InputDigest* FindInput(const std::string& name) const;  // nullptr when absent
};

struct CreateOptions {
  std::string created_utc;  // required: UTC ISO 8601 "YYYY-MM-DDTHH:MM:SS[.fff]Z", from the caller's clock
  std::string session_id;   // empty: DeriveSessionId(path, created_utc)
  // Free space the file system must have beyond the inputs (e.g. planned frames x frame size, C10).
  std::uint64_t min_free_bytes = 0;
  JournalLimits journal_limits;
  CameraMount configuration = CameraMount::kEyeInHand;  // recorded in session.json
};

// What OpenSession found and did, for the session log.
struct OpenReport {
  JournalRecovery journal;                  // the torn tail dropped, if any
  std::vector<std::string> orphans;         // files moved from images/ to orphans/, as "orphans/<name>"
  std::string stale_lock_from;              // the lock line of a dead holder taken over; empty if none
  std::vector<std::string> changed_inputs;  // inputs that differ, accepted through allow_changed_inputs
};

class Session {
 public:
  Session(Session&&) noexcept = default;
  Session& operator=(Session&&) noexcept = default;
  ~Session() = default;  // releases the lock

  const std::string& path() const { return path_; }
  const SessionManifest& manifest() const { return manifest_; }
  Journal& journal() { return journal_; }
  const Journal& journal() const { return journal_; }
  const OpenReport& open_report() const { return report_; }

  // Writes images/<name> atomically without replacing (base/atomic_file.h, Publish::kNoReplace). Call it
  // before appending the record that names ImageRecordPath(name). A file of that name that exists already
  // is accepted only when its content is identical (a retried write); otherwise kInvalidInput: recorded images
  // are never overwritten, so a retaken frame needs a new name (e.g. "<pose id>_<sequence>.png"). kInvalidInput
  // for a name that is not a plain file name; kHardware naming the file for ENOSPC or EIO.
  Status WriteImage(const std::string& name, const std::string& bytes);
  // The same for images/rejected/<name> (created on first use, with a directory fsync of images/): a frame
  // grabbed at a pose that was then skipped, named by RejectedImageRecordPath(name) in its record.
  Status WriteRejectedImage(const std::string& name, const std::string& bytes);

  // kHardware when the session's file system has less than `bytes_needed` bytes available to this user
  // (P5: check before each frame, then halt cleanly rather than run into ENOSPC).
  Status CheckFreeSpace(std::uint64_t bytes_needed) const;

  // The stored copy of input `name`, checked against its recorded size and SHA-256. kInvalidInput when the
  // session has no such input or the copy was modified.
  Result<std::string> ReadInput(const std::string& name) const;

 private:
  Status WriteImageIn(const std::string& directory, const std::string& name, const std::string& bytes);
  friend Result<Session> CreateSession(const std::string&, const SessionInputs&, const std::string&,
                                       const CreateOptions&);
  friend Result<Session> OpenSession(const std::string&, const SessionInputs&, bool, const JournalLimits&, bool);
  Session(std::string path, SessionManifest manifest, Journal journal, SessionLock lock, OpenReport report)
      : path_(std::move(path)),
        manifest_(std::move(manifest)),
        journal_(std::move(journal)),
        lock_(std::move(lock)),
        report_(std::move(report)) {}

  std::string path_;
  SessionManifest manifest_;
  Journal journal_;
  SessionLock lock_;
  OpenReport report_;
};

// Creates a new session in `path` (created; its parent must exist) or in an existing empty directory.
// Refused with kInvalidInput, before anything is written, when: `path` exists and is not an empty directory
// (C10: a session is never overwritten; the message names the path), the directory is not writable, its
// file system has less than the inputs plus options.min_free_bytes available, an input name is not a
// plain file name or repeats, an input exceeds kMaxInputBytes, or an option is invalid. Writes, in order:
// the directory, the lock (held by the returned Session), inputs/ (each file atomically, then 0444),
// images/, an empty journal, and session.json last (atomically): a directory without session.json is an
// interrupted creation, which OpenSession refuses (session_cleanup.h completes or removes it). Errors after the directory exists leave it in place.
Result<Session> CreateSession(const std::string& path, const SessionInputs& inputs, const std::string& software_version,
                              const CreateOptions& options);

// Opens an existing session for writing, to resume it (P2, P3, C9); offline readers such as calibrate use
// ReadSession (session_snapshot.h), which changes nothing. In this order:
//  1. reads session.json strictly (another format or major version, missing, unknown or ill-typed keys:
//     kInvalidInput naming the file and key); images/ and journal.log must exist;
//  2. compares every `expected` input with the recorded SHA-256 (inputs recorded but not expected are
//     not compared); differences are refused with kInvalidInput listing every differing input, unless
//     `allow_changed_inputs` (then listed in open_report().changed_inputs);
//  3. takes the lock (kInvalidInput when in use; a dead holder's lock is taken over and reported only with
//     `take_over_stale_lock`, the operator's confirmation, and refused otherwise: session_lock.h);
//  4. opens the journal with recovery (a torn tail truncated and reported; damage refused);
//  5. moves every non-directory entry of images/ that no durable journal record names (the "image"
//     field of any record, "images/<name>") to orphans/ (a name taken there gets ".1", ".2", ...),
//     reported in open_report().orphans.
// Nothing is changed when steps 1-3 refuse.
Result<Session> OpenSession(const std::string& path, const SessionInputs& expected, bool allow_changed_inputs,
                            const JournalLimits& journal_limits = JournalLimits(), bool take_over_stale_lock = false);

// The `expected` inputs that differ from the ones `manifest` records (by SHA-256), each described with
// its recorded and present size and digest, or "(not recorded in the session)": what OpenSession refuses
// without allow_changed_inputs. Reads nothing.
std::vector<std::string> ChangedInputs(const SessionManifest& manifest, const SessionInputs& expected);
// The refusal of a resume for `changed` (ChangedInputs) inputs of the session at `path`.
Status ChangedInputsRefusal(const std::string& path, const std::vector<std::string>& changed);

// True when `path` holds a session.json, or the lock, inputs/ or journal.log of an interrupted creation:
// what `selfcal calibrate` reads as a session rather than as an observations file (whether the session is
// whole is ReadSession's to say; ReadManifest names an interrupted creation).
bool IsSessionDirectory(const std::string& path);

// Reads and validates `<session>/session.json` without locking or changing anything; *sha256 (optional)
// receives the SHA-256 of the bytes read.
Result<SessionManifest> ReadManifest(const std::string& session_path, std::string* sha256 = nullptr);

// kInvalidInput unless `session_path` has its images/ directory and its journal.log (a missing journal is lost
// data, never started afresh).
Status CheckSessionLayout(const std::string& session_path);

// The stored copy inputs/<digest.name> of a session, checked against the size and SHA-256 its manifest
// recorded. kInvalidInput naming the file when it is missing ("<session>/inputs/<name>: missing, but recorded in
// session.json ...") or differs ("<session>/inputs/<name>: differs from the size or SHA-256 recorded in
// session.json (recorded ...; found ...)").
Result<std::string> ReadRecordedInput(const std::string& session_path, const InputDigest& digest);

// The names of the non-directory entries of <session>/images/ and <session>/images/rejected/ that no record
// names (the "image" field of any record, "images/<name>" or "images/rejected/<name>"), as "<name>" or
// "rejected/<name>", sorted: what OpenSession would move to orphans/ (a rejected one as
// "orphans/rejected_<name>"). Changes nothing.
Result<std::vector<std::string>> UnrecordedImages(const std::string& session_path,
                                                  const std::vector<nlohmann::json>& records);

// "images/<name>": how journal records name an image file.
std::string ImageRecordPath(const std::string& name);
// "images/rejected/<name>": how journal records name a rejected frame's file.
std::string RejectedImageRecordPath(const std::string& name);

// "<created_utc without '-', ':' and '.'>-<first 8 hex digits of the SHA-256 of the absolute, normalised
// path>", e.g. "20250301T120000Z-1a2b3c4d": deterministic, distinct for sessions created at different
// times or places.
std::string DeriveSessionId(const std::string& path, const std::string& created_utc);

}  // namespace selfcal::session

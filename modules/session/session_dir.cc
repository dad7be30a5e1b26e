#include "session/session_dir.h"

#include <dirent.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <optional>
#include <regex>
#include <set>

#include "base/atomic_file.h"
#include "base/sha256.h"
#include "base/terminal_text.h"
#include "session/file_util.h"
#include "session/json_fields.h"

namespace selfcal::session {

namespace {

using internal::Join;
using internal::SafeFileName;
using internal::SystemError;
using internal::WithErrnoErrorCode;

constexpr std::size_t kMaxManifestBytes = std::size_t{1} << 20;

bool ValidUtcTime(const std::string& text) {
  static const std::regex pattern(R"(^(\d{4})-(\d{2})-(\d{2})T(\d{2}):(\d{2}):(\d{2})(\.\d{1,9})?Z$)");
  std::smatch m;
  if (!std::regex_match(text, m, pattern)) return false;
  const int month = std::stoi(m[2]), day = std::stoi(m[3]), hour = std::stoi(m[4]), minute = std::stoi(m[5]),
            second = std::stoi(m[6]);
  return month >= 1 && month <= 12 && day >= 1 && day <= 31 && hour < 24 && minute < 60 && second <= 60;
}

bool ValidSessionId(const std::string& id) {
  static const std::regex pattern(R"(^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$)");
  return std::regex_match(id, pattern);
}

bool IsLowerHex(const std::string& text, std::size_t digits) {
  return text.size() == digits &&
         std::all_of(text.begin(), text.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

// Free bytes available to an unprivileged user on the file system of `directory`.
Result<std::uint64_t> AvailableBytes(const std::string& directory) {
  struct statvfs info {};
  if (::statvfs(directory.c_str(), &info) != 0) return SystemError("cannot query the free space of", directory, errno);
  return static_cast<std::uint64_t>(info.f_bavail) * static_cast<std::uint64_t>(info.f_frsize);
}

Status MakeDirectory(const std::string& path) {
  if (::mkdir(path.c_str(), 0755) != 0) return SystemError("cannot create directory", path, errno);
  return Status::Ok();
}

nlohmann::json ManifestToJson(const SessionManifest& manifest) {
  nlohmann::json inputs = nlohmann::json::array();
  for (const InputDigest& input : manifest.inputs) {
    inputs.push_back({{"name", input.name}, {"bytes", input.bytes}, {"sha256", input.sha256_hex}});
  }
  return {{"format", kSessionFormatName},
          {"version", manifest.version},
          {"session_id", manifest.session_id},
          {"created_utc", manifest.created_utc},
          {"software_version", manifest.software_version},
          {"configuration", CameraMountName(manifest.configuration)},
          {"inputs", inputs}};
}

// Problems of one JSON object's keys (the object at `path`, messages prefixed by `where`): missing
// required ones (at the object's line) and unknown ones (at theirs).
void CheckKeys(const nlohmann::json& object, const JsonPath& path, const std::string& where,
               const std::vector<std::string>& keys, JsonFields* fields, const std::vector<std::string>& optional = {}) {
  for (const std::string& key : keys) {
    if (!object.contains(key)) fields->Add(path, where + "missing key \"" + key + "\"");
  }
  for (const auto& item : object.items()) {
    if (std::find(keys.begin(), keys.end(), item.key()) == keys.end() &&
        std::find(optional.begin(), optional.end(), item.key()) == optional.end()) {
      fields->Add(path.Member(item.key()), where + "unknown key \"" + TerminalSafe(item.key()) + "\"");
    }
  }
}

std::string JoinProblems(const std::vector<std::string>& problems) {
  std::string text;
  for (const std::string& problem : problems) text += (text.empty() ? "" : "; ") + problem;
  return text;
}

// One entry of `inputs` (at `path`, messages prefixed by `where`) into *digest.
void ParseInputDigest(const nlohmann::json& entry, const JsonPath& path, const std::string& where, JsonFields* fields,
                      std::set<std::string>* names, InputDigest* digest) {
  CheckKeys(entry, path, where, {"name", "bytes", "sha256"}, fields);
  if (entry.contains("name") && entry["name"].is_string()) digest->name = entry["name"].get<std::string>();
  if (!SafeFileName(digest->name)) fields->Add(path.Member("name"), where + "\"name\" must be a plain file name");
  if (!names->insert(digest->name).second) {
    fields->Add(path.Member("name"), where + "input \"" + TerminalSafe(digest->name) + "\" repeats");
  }
  if (entry.contains("bytes") && entry["bytes"].is_number_unsigned()) {
    digest->bytes = entry["bytes"].get<std::uint64_t>();
  } else {
    fields->Add(path.Member("bytes"), where + "\"bytes\" must be a non-negative integer");
  }
  if (entry.contains("sha256") && entry["sha256"].is_string()) digest->sha256_hex = entry["sha256"];
  if (!IsLowerHex(digest->sha256_hex, 64)) {
    fields->Add(path.Member("sha256"), where + "\"sha256\" must be 64 lower-case hex digits");
  }
}

// session.json's text; every refusal names `file` and the line ("<file>:<line>: ...", session/json_fields.h).
Result<SessionManifest> ParseManifest(const std::string& text, const std::string& file) {
  JsonFields fields(text, file);
  const std::optional<nlohmann::json> parsed = fields.ParseObject();
  if (!parsed) return fields.ToStatus();
  const nlohmann::json& json = *parsed;
  const JsonPath root;
  if (!json.contains("format") || json["format"] != kSessionFormatName) {
    fields.Add(root.Member("format"), std::string("\"format\" is not \"") + kSessionFormatName + "\": not a selfcal session");
    return fields.ToStatus();
  }
  if (!json.contains("version") || !json["version"].is_number_integer()) {
    fields.Add(root.Member("version"), "\"version\" must be an integer");
    return fields.ToStatus();
  }
  SessionManifest manifest;
  manifest.version = json["version"].get<int>();
  if (manifest.version != kSessionFormatVersion) {
    fields.Add(root.Member("version"), "unknown major version " + std::to_string(manifest.version) +
                                           " (this selfcal reads " + std::to_string(kSessionFormatVersion) + ")");
    return fields.ToStatus();
  }
  CheckKeys(json, root, "", {"format", "version", "session_id", "created_utc", "software_version", "inputs"}, &fields,
            {"configuration"});
  auto string_field = [&](const char* key, std::string* out) {
    if (!json.contains(key)) return;
    if (!json[key].is_string()) {
      fields.Add(root.Member(key), std::string("\"") + key + "\" must be a string");
      return;
    }
    *out = json[key].get<std::string>();
  };
  string_field("session_id", &manifest.session_id);
  string_field("created_utc", &manifest.created_utc);
  string_field("software_version", &manifest.software_version);
  std::string configuration = CameraMountName(CameraMount::kEyeInHand);  // sessions recorded before the key
  string_field("configuration", &configuration);
  if (!ParseCameraMount(configuration, &manifest.configuration)) {
    fields.Add(root.Member("configuration"), "\"configuration\" \"" + TerminalSafe(configuration) +
                                                 "\" is neither \"eye_in_hand\" nor \"eye_to_hand\"");
  }
  if (json.contains("session_id") && !ValidSessionId(manifest.session_id)) {
    fields.Add(root.Member("session_id"),
               "\"session_id\" \"" + TerminalSafe(manifest.session_id) + "\" is not 1-128 of [A-Za-z0-9._-]");
  }
  if (json.contains("created_utc") && !ValidUtcTime(manifest.created_utc)) {
    fields.Add(root.Member("created_utc"), "\"created_utc\" \"" + TerminalSafe(manifest.created_utc) + "\" is not UTC ISO 8601");
  }
  if (json.contains("software_version") && manifest.software_version.empty()) {
    fields.Add(root.Member("software_version"), "\"software_version\" is empty");
  }
  if (json.contains("inputs") && !json["inputs"].is_array()) fields.Add(root.Member("inputs"), "\"inputs\" must be an array");
  if (json.contains("inputs") && json["inputs"].is_array()) {
    std::set<std::string> names;
    for (std::size_t i = 0; i < json["inputs"].size(); ++i) {
      const nlohmann::json& entry = json["inputs"][i];
      const JsonPath at = root.Member("inputs").Element(i);
      const std::string where = "inputs[" + std::to_string(i) + "]: ";
      if (!entry.is_object()) {
        fields.Add(at, where + "must be an object");
        continue;
      }
      InputDigest digest;
      ParseInputDigest(entry, at, where, &fields, &names, &digest);
      manifest.inputs.push_back(digest);
    }
  }
  if (!fields.ok()) return fields.ToStatus();
  return manifest;
}

// Whether `path` is an empty directory; kInvalidInput when it exists but is not a directory.
Result<bool> IsEmptyDirectory(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_directory(path, error)) return Status::InvalidInput(path + " exists and is not a directory");
  const bool empty = std::filesystem::is_empty(path, error);
  if (error) return Status::InvalidInput("cannot list " + path + ": " + error.message());
  return empty;
}

// Names of the entries of `directory` that are not directories, sorted (for a deterministic report).
Result<std::vector<std::string>> ListNonDirectories(const std::string& directory) {
  DIR* dir = ::opendir(directory.c_str());
  if (dir == nullptr) return SystemError("cannot list", directory, errno);
  std::vector<std::string> names;
  while (const dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name;
    if (name == "." || name == "..") continue;
    struct stat info {};
    if (::lstat(Join(directory, name).c_str(), &info) == 0 && !S_ISDIR(info.st_mode)) names.push_back(name);
  }
  ::closedir(dir);
  std::sort(names.begin(), names.end());
  return names;
}

// Moves images/<name> to orphans/<name> (or <name>.1, .2, ... when taken) without ever replacing a file:
// link() then unlink(). A crash between the two leaves the image in both places; the next open moves the
// images/ copy again under a new name. Returns "orphans/<chosen name>".
// A name of UnrecordedImages: "<name>", or "rejected/<name>", which becomes "rejected_<name>" in orphans/.
Result<std::string> MoveToOrphans(const std::string& session_path, const std::string& name) {
  const std::string from = Join(Join(session_path, kImagesDirName), name);
  const std::string orphans = Join(session_path, kOrphansDirName);
  std::string flat = name;
  std::replace(flat.begin(), flat.end(), '/', '_');
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const std::string chosen = attempt == 0 ? flat : flat + "." + std::to_string(attempt);
    if (::link(from.c_str(), Join(orphans, chosen).c_str()) == 0) {
      if (::unlink(from.c_str()) != 0) return SystemError("cannot remove the orphan image", from, errno);
      return std::string(kOrphansDirName) + "/" + chosen;
    }
    if (errno != EEXIST) return SystemError("cannot move the orphan image " + from + " to", orphans, errno);
  }
  return Status::InvalidInput("cannot move the orphan image " + from + ": 1000 names in " + orphans + " are taken");
}

// Moves the files of images/ that no record names to orphans/ (P2).
Result<std::vector<std::string>> MoveOrphans(const std::string& session_path,
                                             const std::vector<nlohmann::json>& records) {
  const std::string images = Join(session_path, kImagesDirName);
  Result<std::vector<std::string>> names = UnrecordedImages(session_path, records);
  if (!names.ok()) return names.status();
  std::vector<std::string> moved;
  for (const std::string& name : *names) {
    const std::string orphans = Join(session_path, kOrphansDirName);
    if (moved.empty() && ::mkdir(orphans.c_str(), 0755) != 0 && errno != EEXIST) {
      return SystemError("cannot create directory", orphans, errno);
    }
    Result<std::string> target = MoveToOrphans(session_path, name);
    if (!target.ok()) return target.status();
    moved.push_back(*target);
  }
  if (!moved.empty()) {
    std::vector<std::string> touched = {images, Join(session_path, kOrphansDirName), session_path};
    const std::string rejected = Join(images, kRejectedDirName);
    std::error_code error;
    if (std::filesystem::is_directory(rejected, error)) touched.insert(touched.begin(), rejected);
    for (const std::string& directory : touched) {
      if (!FsyncDirectory(directory)) return SystemError("cannot fsync directory", directory, errno);
    }
  }
  return moved;
}

}  // namespace

Result<SessionInput> ReadInputFile(const std::string& name, const std::string& path) {
  Result<std::string> bytes = ReadFileCapped(path, kMaxInputBytes);
  if (!bytes.ok()) return Status::InvalidInput("cannot read " + path + ": " + bytes.status().message());
  return SessionInput{name, std::move(bytes).value()};
}

bool IsSessionDirectory(const std::string& path) {
  struct stat st {};
  for (const char* entry : {kManifestFileName, kLockFileName, kInputsDirName, kJournalFileName}) {
    if (::stat((std::filesystem::path(path) / entry).c_str(), &st) == 0) return true;
  }
  return false;
}

Status CheckSessionLayout(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_directory(Join(path, kImagesDirName), error)) {
    return Status::InvalidInput("session " + path + " has no " + kImagesDirName + "/ directory");
  }
  // Created with the session: a missing journal is lost data, never silently started afresh.
  if (!std::filesystem::exists(std::filesystem::symlink_status(Join(path, kJournalFileName), error))) {
    return Status::InvalidInput("session " + path + " has no " + kJournalFileName + ": its records are lost");
  }
  return Status::Ok();
}

Result<std::vector<std::string>> UnrecordedImages(const std::string& session_path,
                                                  const std::vector<nlohmann::json>& records) {
  std::set<std::string> referenced;
  const std::string prefix = std::string(kImagesDirName) + "/";
  for (const nlohmann::json& record : records) {
    const auto image = record.find("image");
    if (image == record.end() || !image->is_string()) continue;
    const std::string& value = image->get_ref<const std::string&>();
    if (value.compare(0, prefix.size(), prefix) == 0) referenced.insert(value.substr(prefix.size()));
  }
  Result<std::vector<std::string>> listed = ListNonDirectories(Join(session_path, kImagesDirName));
  if (!listed.ok()) return listed.status();
  std::vector<std::string> names = std::move(listed).value();
  const std::string rejected_dir = Join(Join(session_path, kImagesDirName), kRejectedDirName);
  std::error_code error;
  if (std::filesystem::is_directory(rejected_dir, error)) {
    Result<std::vector<std::string>> rejected = ListNonDirectories(rejected_dir);
    if (!rejected.ok()) return rejected.status();
    for (const std::string& name : *rejected) names.push_back(std::string(kRejectedDirName) + "/" + name);
  }
  std::vector<std::string> unrecorded;
  for (const std::string& name : names) {
    if (referenced.count(name) == 0) unrecorded.push_back(name);
  }
  std::sort(unrecorded.begin(), unrecorded.end());
  return unrecorded;
}

Result<std::string> ReadRecordedInput(const std::string& session_path, const InputDigest& digest) {
  const std::string file = Join(Join(session_path, kInputsDirName), digest.name);
  const std::string recorded = "recorded " + std::to_string(digest.bytes) + " bytes, sha256 " + digest.sha256_hex;
  bool missing = false;
  Result<std::string> text = ReadFileCapped(file, kMaxInputBytes, &missing);
  if (missing)
    return Status::InvalidInput(file + ": missing, but recorded in " + kManifestFileName + " (" + recorded + ")");
  if (!text.ok()) return WithErrnoErrorCode(text.status());
  const std::string sha256 = Sha256Hex(*text);
  if (text->size() != digest.bytes || sha256 != digest.sha256_hex) {
    return Status::InvalidInput(file + ": differs from the size or SHA-256 recorded in " + kManifestFileName + " (" +
                                recorded + "; found " + std::to_string(text->size()) + " bytes, sha256 " + sha256 +
                                "): the session's stored input was modified");
  }
  return text;
}

const InputDigest* SessionManifest::FindInput(const std::string& name) const {
  for (const InputDigest& input : inputs) {
    if (input.name == name) return &input;
  }
  return nullptr;
}

std::string ImageRecordPath(const std::string& name) { return std::string(kImagesDirName) + "/" + name; }

std::string RejectedImageRecordPath(const std::string& name) {
  return std::string(kImagesDirName) + "/" + kRejectedDirName + "/" + name;
}

std::string DeriveSessionId(const std::string& path, const std::string& created_utc) {
  std::string stamp;
  for (const char c : created_utc) {
    if (c != '-' && c != ':' && c != '.') stamp.push_back(c);
  }
  const std::string absolute = std::filesystem::absolute(path).lexically_normal().string();
  return stamp + "-" + Sha256Hex(absolute).substr(0, 8);
}

Result<SessionManifest> ReadManifest(const std::string& session_path, std::string* sha256) {
  const std::string file = Join(session_path, kManifestFileName);
  bool missing = false;
  Result<std::string> text = ReadFileCapped(file, kMaxManifestBytes, &missing);
  if (missing) {
    struct stat st {};
    if (::stat(Join(session_path, kLockFileName).c_str(), &st) == 0 ||
        ::stat(Join(session_path, kInputsDirName).c_str(), &st) == 0) {
      return Status::InvalidInput(
          "session " + session_path + " was never completely created (its creation was interrupted: no " +
          kManifestFileName +
          "), so nothing was recorded in it: complete it with `selfcal run --resume "
          "--session " +
          session_path + "` (the same options) or remove it with `selfcal session discard " + session_path + "`");
    }
    return Status::InvalidInput(session_path + " is not a selfcal session: it has no " + kManifestFileName);
  }
  if (!text.ok()) return WithErrnoErrorCode(text.status());
  if (sha256 != nullptr) *sha256 = Sha256Hex(*text);
  return ParseManifest(*text, file);
}

Result<Session> CreateSession(const std::string& path, const SessionInputs& inputs, const std::string& software_version,
                              const CreateOptions& options) {
  // Everything is checked before the first write.
  std::vector<std::string> problems;
  if (path.empty()) problems.push_back("the session path is empty");
  if (software_version.empty()) problems.push_back("the software version is empty");
  if (!ValidUtcTime(options.created_utc)) {
    problems.push_back("creation time \"" + options.created_utc + "\" is not UTC ISO 8601 (YYYY-MM-DDTHH:MM:SSZ)");
  }
  if (!options.session_id.empty() && !ValidSessionId(options.session_id)) {
    problems.push_back("session id \"" + options.session_id + "\" is not 1-128 of [A-Za-z0-9._-]");
  }
  std::set<std::string> names;
  std::uint64_t input_bytes = 0;
  for (const SessionInput& input : inputs) {
    if (!SafeFileName(input.name)) problems.push_back("input name \"" + input.name + "\" is not a plain file name");
    if (!names.insert(input.name).second) problems.push_back("input \"" + input.name + "\" is given twice");
    if (input.contents.size() > kMaxInputBytes) {
      problems.push_back("input \"" + input.name + "\" is " + std::to_string(input.contents.size()) +
                         " bytes, more than the limit of " + std::to_string(kMaxInputBytes) + " bytes");
    }
    input_bytes += input.contents.size();
  }
  if (!problems.empty()) return Status::InvalidInput("cannot create session " + path + ": " + JoinProblems(problems));

  std::error_code error;
  const bool exists = std::filesystem::exists(std::filesystem::symlink_status(path, error));
  std::string checked_dir = path;
  if (exists) {
    Result<bool> empty = IsEmptyDirectory(path);
    if (!empty.ok()) return Status::InvalidInput("cannot create session " + path + ": " + empty.status().message());
    if (!*empty) {
      return Status::InvalidInput("session directory " + path +
                                  " exists and is not empty: a session is never overwritten; choose a new directory");
    }
  } else {
    std::filesystem::path normal = std::filesystem::path(path).lexically_normal();
    if (!normal.has_filename()) normal = normal.parent_path();  // "a/b/" names b
    checked_dir = normal.parent_path().string();
    if (checked_dir.empty()) checked_dir = ".";
    if (!std::filesystem::is_directory(checked_dir, error)) {
      return Status::InvalidInput("cannot create session " + path + ": its parent directory " + checked_dir +
                                  " does not exist");
    }
  }
  if (::access(checked_dir.c_str(), W_OK | X_OK) != 0) {
    return Status::InvalidInput("cannot create session " + path + ": " + checked_dir + " is not writable");
  }
  Result<std::uint64_t> available = AvailableBytes(checked_dir);
  if (!available.ok()) return available.status();
  const std::uint64_t needed = options.min_free_bytes + input_bytes;
  if (*available < needed) {
    return Status::InvalidInput("cannot create session " + path + ": only " + std::to_string(*available) +
                                " bytes are free on the file system of " + checked_dir + ", the session needs " +
                                std::to_string(needed) + "");
  }

  if (!exists) {
    if (::mkdir(path.c_str(), 0755) != 0) {
      if (errno == EEXIST)
        return Status::InvalidInput("session directory " + path + " was created meanwhile by another process");
      return SystemError("cannot create session directory", path, errno);
    }
    if (!FsyncDirectory(checked_dir)) return SystemError("cannot fsync directory", checked_dir, errno);
  }
  Result<SessionLock> lock = SessionLock::Acquire(path, /*must_create=*/true);
  if (!lock.ok()) return lock.status();

  SessionManifest manifest;
  manifest.session_id = options.session_id.empty() ? DeriveSessionId(path, options.created_utc) : options.session_id;
  manifest.created_utc = options.created_utc;
  manifest.software_version = software_version;
  manifest.configuration = options.configuration;
  const std::string inputs_dir = Join(path, kInputsDirName);
  if (Status status = MakeDirectory(inputs_dir); !status.ok()) return status;
  for (const SessionInput& input : inputs) {
    const std::string file = Join(inputs_dir, input.name);
    if (Status status = WriteFileAtomically(file, input.contents, Publish::kNoReplace); !status.ok()) {
      return WithErrnoErrorCode(status);
    }
    if (::chmod(file.c_str(), 0444) != 0) return SystemError("cannot make read-only", file, errno);
    manifest.inputs.push_back({input.name, input.contents.size(), Sha256Hex(input.contents)});
  }
  if (Status status = MakeDirectory(Join(path, kImagesDirName)); !status.ok()) return status;
  Result<Journal> journal = Journal::Open(Join(path, kJournalFileName), options.journal_limits);
  if (!journal.ok()) return journal.status();
  // Last: the commit point. Its directory fsync also makes inputs/, images/ and lock durable.
  if (Status status = WriteFileAtomically(Join(path, kManifestFileName), ManifestToJson(manifest).dump(2) + "\n",
                                          Publish::kNoReplace);
      !status.ok()) {
    return WithErrnoErrorCode(status);
  }
  return Session(path, std::move(manifest), std::move(journal).value(), std::move(lock).value(), OpenReport());
}

std::vector<std::string> ChangedInputs(const SessionManifest& manifest, const SessionInputs& expected) {
  std::vector<std::string> changed;
  for (const SessionInput& input : expected) {
    const InputDigest* recorded = manifest.FindInput(input.name);
    if (recorded == nullptr) {
      changed.push_back(input.name + " (not recorded in the session)");
      continue;
    }
    const std::string sha256 = Sha256Hex(input.contents);
    if (sha256 != recorded->sha256_hex) {
      changed.push_back(input.name + " (recorded " + std::to_string(recorded->bytes) + " bytes, sha256 " +
                        recorded->sha256_hex.substr(0, 12) + "...; now " + std::to_string(input.contents.size()) +
                        " bytes, sha256 " + sha256.substr(0, 12) + "...)");
    }
  }
  return changed;
}

Status ChangedInputsRefusal(const std::string& path, const std::vector<std::string>& changed) {
  return Status::InvalidInput("session " + path + " was recorded with other inputs: " + JoinProblems(changed) +
                              "; resume with the same files, or allow changed inputs explicitly");
}

Result<Session> OpenSession(const std::string& path, const SessionInputs& expected, bool allow_changed_inputs,
                            const JournalLimits& journal_limits, bool take_over_stale_lock) {
  Result<SessionManifest> manifest = ReadManifest(path);
  if (!manifest.ok()) return manifest.status();

  OpenReport report;
  report.changed_inputs = ChangedInputs(*manifest, expected);
  if (!report.changed_inputs.empty() && !allow_changed_inputs) return ChangedInputsRefusal(path, report.changed_inputs);
  if (Status s = CheckSessionLayout(path); !s.ok()) return s;

  Result<SessionLock> lock = SessionLock::Acquire(path, false, take_over_stale_lock);
  if (!lock.ok()) return lock.status();
  report.stale_lock_from = lock->stale_from();
  Result<Journal> journal = Journal::Open(Join(path, kJournalFileName), journal_limits);
  if (!journal.ok()) return journal.status();
  report.journal = journal->recovery();
  Result<std::vector<std::string>> orphans = MoveOrphans(path, journal->records());
  if (!orphans.ok()) return orphans.status();
  report.orphans = std::move(orphans).value();
  return Session(path, std::move(manifest).value(), std::move(journal).value(), std::move(lock).value(),
                 std::move(report));
}

Status Session::WriteImage(const std::string& name, const std::string& bytes) {
  return WriteImageIn(Join(path_, kImagesDirName), name, bytes);
}

Status Session::WriteRejectedImage(const std::string& name, const std::string& bytes) {
  const std::string images = Join(path_, kImagesDirName);
  const std::string rejected = Join(images, kRejectedDirName);
  if (::mkdir(rejected.c_str(), 0755) == 0) {
    if (!FsyncDirectory(images)) return SystemError("cannot fsync directory", images, errno);
  } else if (errno != EEXIST) {
    return SystemError("cannot create directory", rejected, errno);
  }
  return WriteImageIn(rejected, name, bytes);
}

Status Session::WriteImageIn(const std::string& directory, const std::string& name, const std::string& bytes) {
  if (!SafeFileName(name)) {
    return Status::InvalidInput("session " + path_ + ": image name \"" + name + "\" is not a plain file name");
  }
  const std::string file = Join(directory, name);
  struct stat info {};
  if (::lstat(file.c_str(), &info) == 0) {
    Result<std::string> existing = ReadFileCapped(file, bytes.size());
    if (existing.ok() && *existing == bytes) return Status::Ok();  // a retried write
    return Status::InvalidInput(
        "image " + file +
        " exists already with other content: recorded images are never overwritten; give the new frame "
        "a new name");
  }
  return WithErrnoErrorCode(WriteFileAtomically(file, bytes, Publish::kNoReplace));
}

Status Session::CheckFreeSpace(std::uint64_t bytes_needed) const {
  Result<std::uint64_t> available = AvailableBytes(path_);
  if (!available.ok()) return available.status();
  if (*available < bytes_needed) {
    return Status::Error(ErrorCode::kHardware, "only " + std::to_string(*available) +
                                                  " bytes are free on the file system of session " + path_ + ", " +
                                                  std::to_string(bytes_needed) + " are needed");
  }
  return Status::Ok();
}

Result<std::string> Session::ReadInput(const std::string& name) const {
  const InputDigest* digest = manifest_.FindInput(name);
  if (digest == nullptr) return Status::InvalidInput("session " + path_ + " has no input \"" + name + "\"");
  return ReadRecordedInput(path_, *digest);
}

}  // namespace selfcal::session

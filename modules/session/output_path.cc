#include "session/output_path.h"

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include "session/journal.h"
#include "session/session_dir.h"

namespace selfcal::session {

namespace {

namespace fs = std::filesystem;

// Absolute, with the symlinks and `..` of the existing part resolved and no trailing separator.
fs::path Resolve(const std::string& path) {
  std::error_code error;
  fs::path resolved = fs::weakly_canonical(fs::absolute(path, error), error);
  if (error) resolved = fs::absolute(path, error).lexically_normal();
  while (!resolved.empty() && resolved.filename().empty() && resolved != resolved.root_path()) {
    resolved = resolved.parent_path();  // "a/b/" names b
  }
  return resolved;
}

bool IsRegularFile(const fs::path& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode);
}

bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  return ::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

// The nearest ancestor of `resolved` (itself excluded) that exists.
fs::path NearestExistingAncestor(const fs::path& resolved) {
  std::error_code error;
  fs::path p = resolved.parent_path();
  while (!p.empty() && p != p.root_path() && !fs::exists(p, error)) p = p.parent_path();
  return p.empty() ? fs::path("/") : p;
}

bool WritableDirectory(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(path, error) && ::access(path.c_str(), W_OK | X_OK) == 0;
}

}  // namespace

const char* OutputKindName(OutputKind kind) {
  switch (kind) {
    case OutputKind::kFile: return "file";
    case OutputKind::kFileAndParents: return "file";
    case OutputKind::kDirectory: return "directory";
    case OutputKind::kUpdatedFile: return "updated-file";
    case OutputKind::kSessionDirectory: return "session";
  }
  return "file";
}

std::string EnclosingSession(const std::string& path) {
  for (fs::path p = Resolve(path); !p.empty(); p = p.parent_path()) {
    if (IsRegularFile(p / kManifestFileName) || IsRegularFile(p / kJournalFileName)) return p.string();
    if (p == p.root_path()) break;
  }
  return "";
}

Status CheckOutputPath(const OutputPath& output, const std::vector<std::string>& inputs, bool force) {
  if (output.path.empty()) return Status::Ok();
  const std::string what = output.option + " " + output.path;
  auto refuse = [&](const std::string& why) {
    return Status::Error(ErrorCode::kInvalidInput, what + ": " + why + "; nothing was written");
  };
  const fs::path resolved = Resolve(output.path);
  const bool creates_session = output.kind == OutputKind::kSessionDirectory;
  const std::string enclosing = EnclosingSession(creates_session ? resolved.parent_path().string() : output.path);
  if (!enclosing.empty()) {
    const bool is_session = resolved == fs::path(enclosing);
    return refuse(std::string(is_session ? "is the session directory " : "lies inside the session directory ") +
                  enclosing + ": no command writes into a session, not even with --force; choose a path outside it");
  }
  for (const std::string& input : inputs) {
    if (SameFile(resolved.string(), input)) return refuse("is " + input + ", an input of this command; choose another path");
    for (const std::string& name : output.files) {
      if (SameFile((resolved / name).string(), input)) {
        return refuse("would replace " + name + " there, which is " + input +
                      ", an input of this command; choose another directory");
      }
    }
  }
  std::error_code error;
  const bool exists = fs::exists(resolved, error);
  const bool is_directory = exists && fs::is_directory(resolved, error);
  switch (output.kind) {
    case OutputKind::kFile:
    case OutputKind::kFileAndParents:
      if (is_directory) return refuse("is a directory; give a file name");
      if (exists && !force) return refuse("exists; give --force to replace it, or another path");
      if (output.kind == OutputKind::kFile && !WritableDirectory(resolved.parent_path())) {
        return refuse("its directory " + resolved.parent_path().string() + " does not exist or is not writable");
      }
      if (!WritableDirectory(NearestExistingAncestor(resolved))) {
        return refuse(NearestExistingAncestor(resolved).string() + " is not a writable directory");
      }
      return Status::Ok();
    case OutputKind::kDirectory: {
      if (exists && !is_directory) return refuse("exists and is not a directory");
      const fs::path writable = is_directory ? resolved : NearestExistingAncestor(resolved);
      if (!WritableDirectory(writable)) return refuse(writable.string() + " is not a writable directory");
      if (force || !is_directory) return Status::Ok();
      for (const std::string& name : output.files) {
        if (fs::exists(resolved / name, error)) {
          return refuse("holds " + name + " already (of an earlier run?); give --force to replace the files this "
                        "command writes there, or another directory");
        }
      }
      return Status::Ok();
    }
    case OutputKind::kUpdatedFile: return Status::Ok();
    case OutputKind::kSessionDirectory:
      if (exists && !is_directory) return refuse("exists and is not a directory");
      return Status::Ok();
  }
  return Status::Ok();
}

}  // namespace selfcal::session

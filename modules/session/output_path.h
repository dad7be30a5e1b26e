// The one rule for every path a command writes (../shared/RELIABILITY.md C9, C10; docs/cli-output.md "Output paths"):
// nothing is written inside a session directory, over an input the command reads, or over an existing
// file unless the user said so (--force). Checked for every output option before any work: a refusal
// leaves everything as it was.
#pragma once

#include <string>
#include <vector>

#include "base/status.h"

namespace selfcal::session {

enum class OutputKind {
  kFile,             // a file written (its directory must exist); an existing one replaced only with force
  kFileAndParents,   // the same, its missing directories created
  kDirectory,        // a directory (created when missing) the command writes `files` into; refused when it
                     // holds any of them, unless force
  kUpdatedFile,      // an input the command updates on purpose (name-dots --setup): the session rule only
  kSessionDirectory, // a session created or resumed (run --session): none of its ancestors may be a session
};

// "file", "directory", ...: the kind's name in listings and messages.
const char* OutputKindName(OutputKind kind);

struct OutputPath {
  std::string option;  // as the user types it: "--out", "--write-camera-opencv"
  std::string path;    // as given (relative to the working directory); empty: not written, not checked
  OutputKind kind = OutputKind::kFile;
  std::vector<std::string> files{};  // kDirectory: the names the command writes into it
};

// The session directory that is `path` or one of its ancestors, with symlinks and `..` of the existing part
// resolved (a directory holding session.json, or journal.log of a creation not yet finished); "" when none.
std::string EnclosingSession(const std::string& path);

// Checks one output path; kInvalidInput (exit 2) naming the option, the path and why:
//  - it is, or lies inside, a session directory (for kSessionDirectory: an ancestor is one) - even with force;
//  - it is the same file (same inode) as one of `inputs` (paths the command reads; missing ones ignored), or
//    for kDirectory one of the files it writes there is - even with force;
//  - kFile, kFileAndParents: it is a directory; or it exists and `force` is false; kFile: its directory does
//    not exist or is not writable; kFileAndParents: its nearest existing ancestor is not a writable directory;
//  - kDirectory: it exists and is not a directory; it holds one of `files` and `force` is false; it or its
//    nearest existing ancestor is not writable.
Status CheckOutputPath(const OutputPath& output, const std::vector<std::string>& inputs, bool force);

}  // namespace selfcal::session

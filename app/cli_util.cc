#include "app/cli_util.h"

#include <filesystem>
#include <iostream>

#include "base/sha256.h"

namespace selfcal::app {

std::string ResolveDataPath(const std::string& path) {
  namespace fs = std::filesystem;
  if (fs::exists(path) || fs::path(path).is_absolute()) return path;
  const fs::path in_source = fs::path(SELFCAL_SOURCE_DIR) / path;
  return fs::exists(in_source) ? in_source.string() : path;
}

int Fail(const Status& status) {
  std::cerr << "selfcal: " << status.ToString() << "\n";
  return static_cast<int>(status.code());
}

ExitCode ExitCodeFor(pipeline::Outcome outcome) {
  switch (outcome) {
    case pipeline::Outcome::kSuccess: return ExitCode::kOk;
    case pipeline::Outcome::kInvalidInput: return ExitCode::kUsage;
    case pipeline::Outcome::kDegenerate:
    case pipeline::Outcome::kScaleUnresolved: return ExitCode::kDegenerateData;
    case pipeline::Outcome::kUnconverged:
    case pipeline::Outcome::kSolverFailure:
    case pipeline::Outcome::kNotRun: return ExitCode::kSolverFailure;
  }
  return ExitCode::kSolverFailure;
}

ExitCode ExitCodeFor(bundle::Outcome outcome) {
  switch (outcome) {
    case bundle::Outcome::kConverged: return ExitCode::kOk;
    case bundle::Outcome::kInvalidInput: return ExitCode::kUsage;
    case bundle::Outcome::kDegenerate:
    case bundle::Outcome::kScaleUnresolved: return ExitCode::kDegenerateData;
    case bundle::Outcome::kNoConvergence:
    case bundle::Outcome::kFailure:
    case bundle::Outcome::kNotRun: return ExitCode::kSolverFailure;
  }
  return ExitCode::kSolverFailure;
}

std::string FileSha256(const std::string& path) {
  Result<std::string> digest = Sha256OfFile(path);
  return digest.ok() ? *digest : std::string();
}

Status EnsureDirectory(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_directory(path, ec)) {
    return Status::Error(ExitCode::kUsage, "output `" + path + "` exists and is not a directory");
  }
  fs::create_directories(path, ec);
  if (ec) return Status::Error(ExitCode::kUsage, "cannot create output directory `" + path + "`: " + ec.message());
  return Status::Ok();
}

}  // namespace selfcal::app

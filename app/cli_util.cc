#include "app/cli_util.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace selfcal::app {

std::string ResolveDataPath(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;  // a symlink loop or an unreadable folder: not found here, the reader says why
  if (fs::exists(path, ec) || fs::path(path).is_absolute()) return path;
  const fs::path in_source = fs::path(SELFCAL_SOURCE_DIR) / path;
  return fs::exists(in_source, ec) ? in_source.string() : path;
}

int Fail(const Status& status) {
  std::cerr << "selfcal: " << status.ToString() << "\n";
  return static_cast<int>(status.code());
}

ExitCode ExitCodeFor(calibration::Verdict verdict) {
  switch (verdict) {
    case calibration::Verdict::kAccepted: return ExitCode::kOk;
    case calibration::Verdict::kInvalidInput: return ExitCode::kUsage;
    case calibration::Verdict::kDegenerate:
    case calibration::Verdict::kScaleUnresolved: return ExitCode::kDegenerateData;
    case calibration::Verdict::kUnconverged:
    case calibration::Verdict::kSolverFailure: return ExitCode::kSolverFailure;
  }
  return ExitCode::kSolverFailure;
}

std::string FileHash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  uint64_t hash = 1469598103934665603ULL;
  char buffer[65536];
  while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      hash ^= static_cast<unsigned char>(buffer[i]);
      hash *= 1099511628211ULL;
    }
  }
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(hash));
  return hex;
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

#include "base/status.h"

namespace selfcal {

const char* ExitCodeName(ExitCode code) {
  switch (code) {
    case ExitCode::kOk: return "ok";
    case ExitCode::kUsage: return "usage_or_config";
    case ExitCode::kDegenerateData: return "degenerate_data";
    case ExitCode::kHardware: return "hardware_fault";
    case ExitCode::kSolverFailure: return "solver_failure";
    case ExitCode::kInterrupted: return "interrupted";
  }
  return "unknown";
}

std::string Status::ToString() const {
  if (ok()) return "ok";
  return std::string(ExitCodeName(code_)) + ": " + message_;
}

namespace internal {
void ThrowCheckFailure(const char* condition, const char* file, int line, const std::string& message) {
  std::ostringstream out;
  out << "check failed: " << condition << " (" << file << ":" << line << ")";
  if (!message.empty()) out << ": " << message;
  throw InvalidArgument(out.str());
}
}  // namespace internal

}  // namespace selfcal

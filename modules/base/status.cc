#include "base/status.h"

namespace selfcal {

const char* ErrorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk: return "ok";
    case ErrorCode::kInvalidInput: return "invalid_input";
    case ErrorCode::kDegenerateData: return "degenerate_data";
    case ErrorCode::kHardware: return "hardware_fault";
    case ErrorCode::kSolverFailure: return "solver_failure";
    case ErrorCode::kInterrupted: return "interrupted";
    case ErrorCode::kInternal: return "internal_error";
  }
  return "unknown";
}

std::string Status::ToString() const {
  if (ok()) return "ok";
  return std::string(ErrorCodeName(code_)) + ": " + message_;
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

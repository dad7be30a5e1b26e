// The process exit codes of selfcal and selfcal-robot-sim (../shared/RELIABILITY.md design rule 2; README.md), and
// the one mapping from the library's error codes to them. Only app/ chooses exit codes.
#pragma once

#include "base/status.h"

namespace selfcal::app {

enum class ExitCode : int {
  kOk = 0,
  kUsage = 2,           // usage or configuration error
  kDegenerateData = 3,  // insufficient or degenerate data
  kHardware = 4,        // robot or camera fault (the session halted)
  kSolverFailure = 5,   // the solver did not converge or failed
  kModelRejected = 6,   // converged, but the model fails its held-out checks (no model written)
  kOutsideLimits = 7,   // compensate: a target is reachable only outside the joint limits (nothing written)
  kUntested = 8,        // converged and passed what could be checked, but no held-out test: model written, unverified
  kInternal = 70,       // a bug in selfcal (sysexits.h EX_SOFTWARE): please report it
  kInterrupted = 130,   // Ctrl-C: the robot was stopped, the session is resumable
};

inline ExitCode ExitCodeFor(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk: return ExitCode::kOk;
    case ErrorCode::kInvalidInput: return ExitCode::kUsage;
    case ErrorCode::kDegenerateData: return ExitCode::kDegenerateData;
    case ErrorCode::kHardware: return ExitCode::kHardware;
    case ErrorCode::kSolverFailure: return ExitCode::kSolverFailure;
    case ErrorCode::kInterrupted: return ExitCode::kInterrupted;
    case ErrorCode::kInternal: return ExitCode::kInternal;
  }
  return ExitCode::kInternal;
}

inline const char* ExitCodeName(ExitCode code) {
  switch (code) {
    case ExitCode::kOk: return "ok";
    case ExitCode::kUsage: return "usage_or_config";
    case ExitCode::kDegenerateData: return "degenerate_data";
    case ExitCode::kHardware: return "hardware_fault";
    case ExitCode::kSolverFailure: return "solver_failure";
    case ExitCode::kModelRejected: return "model_rejected";
    case ExitCode::kUntested: return "untested";
    case ExitCode::kOutsideLimits: return "outside_joint_limits";
    case ExitCode::kInternal: return "internal_error";
    case ExitCode::kInterrupted: return "interrupted";
  }
  return "unknown";
}

}  // namespace selfcal::app

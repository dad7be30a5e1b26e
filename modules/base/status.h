// Module base (the bottom layer; ARCHITECTURE.md): Status / Result<T> with a domain ErrorCode (invalid
// input, degenerate data, hardware, solver, interrupted, internal; the exit codes are chosen in app/exit_codes.h
// only) and SELFCAL_CHECK (this header); and the small services every layer shares:
//   atomic_file.h         atomic file publication and size-capped reads (io, capture and session use it)
//   crc32.h, sha256.h     CRC-32 (zlib, private) and SHA-256 (nettle, private: OpenSSL's libcrypto cost 3 ms of
//                         every start): session journals and manifests, report provenance
//   progress.h            ProgressSink, the abstract progress of a long step (an optional pointer in the options
//                         of RunStudy, PlanMeasurements, Calibrate, RunSession's context, DetectAllImagePoints)
//   terminal_text.h       TerminalSafe: control characters of controller and file text escaped for a terminal
//   closest_name.h        EditDistance / ClosestName: did-you-mean for YAML keys and the CLI
//   json_lines.h          JsonLines: the line of every key of a JSON text and the first repeated key, for
//                         refusals of setup.json and session.json that name file:line (nlohmann_json private)
//   process_heap.h        PrepareProcessHeap: malloc's large steps and transparent huge pages, first in main
//   time_limited_child.h  RunInTimeLimitedChild: work in a forked child killed at a wall-clock limit (OpenCV's
//                         YAML reader loops forever on some camera files); a crash of the child told apart
//   xml_scan.h            ScanXml: size, depth, tags (optionally UTF-8, repeated siblings) of an XML text checked
//                         without recursion before a parser sees it (URDFs, ViSP and OpenCV camera files)
//   install_layout.h      FindDataFile: config/, plotly.min.js and the private library found from the program's
//                         own location (cmake/SelfcalInstall.cmake); the source tree only from a build tree
//
// Error and outcome vocabulary shared by every module.
//
// Three kinds of failure, three mechanisms (../shared/STYLE.md, "Errors"):
//  - expected numerical outcomes (degenerate data, too few points, no convergence) are enum values in
//    each estimator's report, never exceptions;
//  - caller or programmer errors (size mismatch, NaN input) throw selfcal::InvalidArgument through
//    SELFCAL_CHECK;
//  - environment, file and configuration problems travel as a Status (or Result<T>) carrying an
//    ErrorCode; the CLI alone maps it to the documented exit codes (../shared/RELIABILITY.md, design rule 2).
#pragma once

#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace selfcal {

// What went wrong, in the library's words. The application maps each to a process exit code
// (app/exit_codes.h; ../shared/RELIABILITY.md design rule 2); no library chooses exit codes.
enum class ErrorCode : int {
  kOk = 0,
  kInvalidInput,    // usage, configuration or file content the user can fix (names file, key, line, value)
  kDegenerateData,  // insufficient or degenerate data
  kHardware,        // robot or camera fault
  kSolverFailure,   // the solver did not produce a usable result
  kInterrupted,     // a stop request (Ctrl-C)
  kInternal,        // a broken invariant inside selfcal: a bug, never the user's input
};

const char* ErrorCodeName(ErrorCode code);

// Thrown by SELFCAL_CHECK for caller errors. Never thrown inside Ceres functors.
class InvalidArgument : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class Status {
 public:
  Status() = default;  // OK
  static Status Ok() { return Status(); }
  static Status Error(ErrorCode code, std::string message) { return Status(code, std::move(message)); }
  // A configuration or input error (kInvalidInput): the message names the file, key, line or value.
  static Status InvalidInput(std::string message) { return Status(ErrorCode::kInvalidInput, std::move(message)); }

  bool ok() const { return code_ == ErrorCode::kOk; }
  ErrorCode code() const { return code_; }
  const std::string& message() const { return message_; }
  std::string ToString() const;

  // An optional machine-readable detail finer than the ErrorCode, for callers that must tell failures
  // apart (e.g. capture::CaptureError: a camera that timed out is retried, a missing one is not).
  // `domain` names the enum the value belongs to (a string literal, e.g. "capture"); an error without
  // a detail has detail_domain() == "" and detail() == 0. Ignored on an OK status.
  Status WithDetail(const char* domain, int detail) const {
    Status copy = *this;
    if (!copy.ok()) {
      copy.detail_domain_ = domain != nullptr ? domain : "";
      copy.detail_ = detail;
    }
    return copy;
  }
  const char* detail_domain() const { return detail_domain_; }
  int detail() const { return detail_; }

 private:
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
  const char* detail_domain_ = "";
  int detail_ = 0;
};

// A value or the Status explaining why there is none.
template <typename T>
class Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  Result(Status status) : status_(std::move(status)) {  // NOLINT
    if (status_.ok()) throw InvalidArgument("Result constructed from an OK status without a value");
  }
  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }
  const T& value() const& { return Checked(); }
  T& value() & { return const_cast<T&>(Checked()); }
  T&& value() && { return std::move(const_cast<T&>(Checked())); }
  const T& operator*() const& { return Checked(); }
  const T* operator->() const { return &Checked(); }

 private:
  const T& Checked() const {
    if (!value_) throw InvalidArgument("Result::value() on an error: " + status_.ToString());
    return *value_;
  }
  std::optional<T> value_;
  Status status_;
};

namespace internal {
[[noreturn]] void ThrowCheckFailure(const char* condition, const char* file, int line,
                                    const std::string& message);
}  // namespace internal

}  // namespace selfcal

// SELFCAL_CHECK(cond, message-stream): throws selfcal::InvalidArgument naming the condition.
//   SELFCAL_CHECK(a.size() == b.size(), "sizes " << a.size() << " vs " << b.size());
#define SELFCAL_CHECK(condition, message)                                                    \
  do {                                                                                       \
    if (!(condition)) {                                                                      \
      std::ostringstream selfcal_check_stream_;                                              \
      selfcal_check_stream_ << message;                                                      \
      ::selfcal::internal::ThrowCheckFailure(#condition, __FILE__, __LINE__,                 \
                                             selfcal_check_stream_.str());                   \
    }                                                                                        \
  } while (false)

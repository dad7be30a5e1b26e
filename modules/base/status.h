// Error and outcome vocabulary shared by every module.
//
// Three kinds of failure, three mechanisms (STYLE.md, "Errors"):
//  - expected numerical outcomes (degenerate data, too few points, no convergence) are enum values in
//    each estimator's report, never exceptions;
//  - caller or programmer errors (size mismatch, NaN input) throw selfcal::InvalidArgument through
//    SELFCAL_CHECK;
//  - environment, file and configuration problems travel as a Status (or Result<T>) carrying an ExitCode
//    so that the CLI maps them to the documented exit codes (RELIABILITY.md, design rule 2).
#pragma once

#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace selfcal {

// Process exit codes (RELIABILITY.md, design rule 2).
enum class ExitCode : int {
  kOk = 0,
  kUsage = 2,          // usage or configuration error (C1-C11)
  kDegenerateData = 3, // insufficient or degenerate data
  kHardware = 4,       // robot or camera fault
  kSolverFailure = 5,  // the solver did not produce a usable result
  kInterrupted = 130,
};

const char* ExitCodeName(ExitCode code);

// Thrown by SELFCAL_CHECK for caller errors. Never thrown inside Ceres functors.
class InvalidArgument : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class Status {
 public:
  Status() = default;  // OK
  static Status Ok() { return Status(); }
  static Status Error(ExitCode code, std::string message) { return Status(code, std::move(message)); }

  bool ok() const { return code_ == ExitCode::kOk; }
  ExitCode code() const { return code_; }
  const std::string& message() const { return message_; }
  std::string ToString() const;

  // An optional machine-readable detail finer than the ExitCode, for callers that must tell failures
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
  Status(ExitCode code, std::string message) : code_(code), message_(std::move(message)) {}
  ExitCode code_ = ExitCode::kOk;
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

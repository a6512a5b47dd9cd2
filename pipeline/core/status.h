// Status and StatusOr: how expected failures travel (a short read, a wrong format, no lattice,
// a full disk, a vanished camera). Modelled on absl::Status. Our own bugs use PX_CHECK instead.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

#include "pipeline/core/check.h"

namespace px {

enum class StatusCode {
  kOk = 0,
  kCancelled,
  kInvalidArgument,   // the caller's input is wrong (bad option, malformed file)
  kDeadlineExceeded,  // a timeout elapsed (camera did not deliver in time)
  kNotFound,          // a file, camera or lattice that should exist does not
  kAlreadyExists,
  kResourceExhausted,   // disk full, quota reached, out of memory
  kFailedPrecondition,  // the system is not in a state to do this (not configured)
  kOutOfRange,
  kUnimplemented,
  kInternal,
  kUnavailable,       // a device went away or is busy; may work later
  kDataLoss,          // truncated or corrupt data
  kPermissionDenied,  // the caller may not do this (a control-socket peer of another user)
  kAborted,           // cut short from outside: a worker process killed by a signal or a limit
};

std::string_view StatusCodeName(StatusCode code);
// The inverse of StatusCodeName (for statuses carried across a process boundary); nullopt for an
// unknown name.
std::optional<StatusCode> StatusCodeFromName(std::string_view name);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // "INVALID_ARGUMENT: view 4: got 1920x1080 NV12, want 4056x3040 SRGGB12"
  std::string ToString() const;
  // Returns a copy whose message is "context: message" (no-op on OK).
  Status WithContext(std::string_view context) const;

  friend bool operator==(const Status& a, const Status& b) { return a.code_ == b.code_ && a.message_ == b.message_; }

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

inline Status OkStatus() { return Status(); }
inline Status InvalidArgumentError(std::string m) { return {StatusCode::kInvalidArgument, std::move(m)}; }
inline Status NotFoundError(std::string m) { return {StatusCode::kNotFound, std::move(m)}; }
inline Status DataLossError(std::string m) { return {StatusCode::kDataLoss, std::move(m)}; }
inline Status UnavailableError(std::string m) { return {StatusCode::kUnavailable, std::move(m)}; }
inline Status InternalError(std::string m) { return {StatusCode::kInternal, std::move(m)}; }
inline Status FailedPreconditionError(std::string m) { return {StatusCode::kFailedPrecondition, std::move(m)}; }
inline Status ResourceExhaustedError(std::string m) { return {StatusCode::kResourceExhausted, std::move(m)}; }
inline Status DeadlineExceededError(std::string m) { return {StatusCode::kDeadlineExceeded, std::move(m)}; }
inline Status OutOfRangeError(std::string m) { return {StatusCode::kOutOfRange, std::move(m)}; }
inline Status CancelledError(std::string m) { return {StatusCode::kCancelled, std::move(m)}; }
inline Status UnimplementedError(std::string m) { return {StatusCode::kUnimplemented, std::move(m)}; }
inline Status PermissionDeniedError(std::string m) { return {StatusCode::kPermissionDenied, std::move(m)}; }
inline Status AbortedError(std::string m) { return {StatusCode::kAborted, std::move(m)}; }

template <typename T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(const Status& status) : value_(status) {  // NOLINT: implicit by design
    PX_CHECK(!status.ok()) << "StatusOr constructed from an OK status without a value";
  }
  StatusOr(Status&& status) : value_(std::move(status)) {  // NOLINT
    PX_CHECK(!std::get<Status>(value_).ok()) << "StatusOr constructed from an OK status";
  }
  StatusOr(const T& value) : value_(value) {}        // NOLINT
  StatusOr(T&& value) : value_(std::move(value)) {}  // NOLINT

  bool ok() const { return std::holds_alternative<T>(value_); }
  Status status() const { return ok() ? OkStatus() : std::get<Status>(value_); }

  const T& value() const& {
    PX_CHECK(ok()) << "StatusOr::value() on error: " << std::get<Status>(value_).ToString();
    return std::get<T>(value_);
  }
  T& value() & {
    PX_CHECK(ok()) << "StatusOr::value() on error: " << std::get<Status>(value_).ToString();
    return std::get<T>(value_);
  }
  T&& value() && {
    PX_CHECK(ok()) << "StatusOr::value() on error: " << std::get<Status>(value_).ToString();
    return std::get<T>(std::move(value_));
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

 private:
  std::variant<Status, T> value_;
};

}  // namespace px

#define PX_STATUS_CONCAT_INNER(a, b) a##b
#define PX_STATUS_CONCAT(a, b) PX_STATUS_CONCAT_INNER(a, b)

// Returns from the enclosing function if `expr` (a Status) is not OK.
#define PX_RETURN_IF_ERROR(expr)                     \
  do {                                               \
    ::px::Status px_status_tmp_ = (expr);            \
    if (!px_status_tmp_.ok()) return px_status_tmp_; \
  } while (0)

// PX_ASSIGN_OR_RETURN(auto x, MakeX()); returns the error if MakeX() failed.
#define PX_ASSIGN_OR_RETURN(lhs, expr) PX_ASSIGN_OR_RETURN_IMPL(PX_STATUS_CONCAT(px_statusor_, __LINE__), lhs, expr)
#define PX_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                             \
  if (!tmp.ok()) return tmp.status();            \
  lhs = std::move(tmp).value()

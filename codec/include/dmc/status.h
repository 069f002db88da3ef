// Status and StatusOr: how every fallible dmc call reports failure.
//
// Contract:
//  - No exception crosses the public API; every fallible function returns Status or StatusOr<T>.
//  - An error carries a pinned ErrorCode (its numeric value is frozen and documented in the
//    README and the bitstream spec) and a message that names the file, frame and element at fault.
//  - The CLI maps each code to its own process exit code (ExitCodeFor), so scripts can tell
//    classes of failure apart.
#pragma once

#include <cassert>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace dmc {

// Frozen numeric values: never renumber, only append.
enum class ErrorCode : int {
  kOk = 0,
  kInvalidArgument = 1,   // impossible option or parameter value
  kIoError = 2,           // cannot open, read, write or rename a file
  kParseError = 3,        // a file's syntax is malformed
  kInvalidSequence = 4,   // the mesh sequence breaks a model invariant (indices, NaN, empty)
  kMismatch = 5,          // two inputs that must agree do not (vertex counts, triangle lists)
  kUnsupported = 6,       // a well-formed request this build or format version cannot do
  kCorruptStream = 7,     // a .dmc stream fails a checksum or holds an impossible value
  kTruncatedStream = 8,   // a .dmc stream ends before a declared field ends
  kNumericalFailure = 9,  // a factorisation or solve failed (singular, non-finite)
  kNotFound = 10,         // an unknown name or ID (operator, method, generator)
  kInternal = 11,         // a broken internal invariant: a bug in dmc
  kResourceLimit = 12,    // the work or memory a request needs exceeds a limit (or memory ran out)
};

// Stable lower-case name of a code, e.g. "invalid-argument".
std::string_view ErrorCodeName(ErrorCode code);

// Process exit code the dmc CLI uses for a code: 0 for kOk, otherwise 10 + the code's value.
// (1 stays reserved for usage errors reported by the argument parser.)
int ExitCodeFor(ErrorCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;  // OK
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == ErrorCode::kOk; }
  ErrorCode code() const { return code_; }
  const std::string& message() const { return message_; }

  // "invalid-argument: <message>", or "ok".
  std::string ToString() const;

  // Returns a copy whose message is prefixed with `context: ` (e.g. the file being read), keeping
  // the code, so the cause is never lost while the location is added.
  Status WithContext(std::string_view context) const;

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

Status InvalidArgumentError(std::string message);
Status IoError(std::string message);
Status ParseError(std::string message);
Status InvalidSequenceError(std::string message);
Status MismatchError(std::string message);
Status UnsupportedError(std::string message);
Status CorruptStreamError(std::string message);
Status TruncatedStreamError(std::string message);
Status NumericalFailureError(std::string message);
Status NotFoundError(std::string message);
Status InternalError(std::string message);
Status ResourceLimitError(std::string message);

// Either a value or a non-OK Status. Constructing from an OK Status is a bug (becomes kInternal).
template <typename T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(const T& value) : storage_(value) {}        // NOLINT(google-explicit-constructor)
  StatusOr(T&& value) : storage_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  StatusOr(Status status)                              // NOLINT(google-explicit-constructor)
      : storage_(status.ok() ? InternalError("StatusOr constructed from an OK status")
                             : std::move(status)) {}

  bool ok() const { return std::holds_alternative<T>(storage_); }
  Status status() const { return ok() ? Status::Ok() : std::get<Status>(storage_); }

  const T& value() const& {
    assert(ok());
    return std::get<T>(storage_);
  }
  T& value() & {
    assert(ok());
    return std::get<T>(storage_);
  }
  T&& value() && {
    assert(ok());
    return std::get<T>(std::move(storage_));
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

 private:
  std::variant<Status, T> storage_;
};

}  // namespace dmc

#define DMC_STATUS_CONCAT_INNER_(a, b) a##b
#define DMC_STATUS_CONCAT_(a, b) DMC_STATUS_CONCAT_INNER_(a, b)

// Returns the Status of `expr` from the enclosing function if it is not OK.
#define DMC_RETURN_IF_ERROR(expr)                      \
  do {                                                 \
    ::dmc::Status dmc_status_tmp_ = (expr);            \
    if (!dmc_status_tmp_.ok()) return dmc_status_tmp_; \
  } while (false)

// `DMC_ASSIGN_OR_RETURN(auto x, MakeX());` declares/assigns x from a StatusOr, or returns its
// error.
#define DMC_ASSIGN_OR_RETURN(lhs, expr) \
  DMC_ASSIGN_OR_RETURN_IMPL_(DMC_STATUS_CONCAT_(dmc_statusor_, __LINE__), lhs, expr)
#define DMC_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, expr) \
  auto tmp = (expr);                               \
  if (!tmp.ok()) return tmp.status();              \
  lhs = std::move(tmp).value()

#include "dmc/status.h"

namespace dmc {

std::string_view ErrorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk:
      return "ok";
    case ErrorCode::kInvalidArgument:
      return "invalid-argument";
    case ErrorCode::kIoError:
      return "io-error";
    case ErrorCode::kParseError:
      return "parse-error";
    case ErrorCode::kInvalidSequence:
      return "invalid-sequence";
    case ErrorCode::kMismatch:
      return "mismatch";
    case ErrorCode::kUnsupported:
      return "unsupported";
    case ErrorCode::kCorruptStream:
      return "corrupt-stream";
    case ErrorCode::kTruncatedStream:
      return "truncated-stream";
    case ErrorCode::kNumericalFailure:
      return "numerical-failure";
    case ErrorCode::kNotFound:
      return "not-found";
    case ErrorCode::kInternal:
      return "internal";
    case ErrorCode::kResourceLimit:
      return "resource-limit";
  }
  return "unknown";
}

int ExitCodeFor(ErrorCode code) { return code == ErrorCode::kOk ? 0 : 10 + static_cast<int>(code); }

std::string Status::ToString() const {
  if (ok()) return "ok";
  return std::string(ErrorCodeName(code_)) + ": " + message_;
}

Status Status::WithContext(std::string_view context) const {
  if (ok()) return *this;
  return Status(code_, std::string(context) + ": " + message_);
}

Status InvalidArgumentError(std::string message) {
  return {ErrorCode::kInvalidArgument, std::move(message)};
}
Status IoError(std::string message) { return {ErrorCode::kIoError, std::move(message)}; }
Status ParseError(std::string message) { return {ErrorCode::kParseError, std::move(message)}; }
Status InvalidSequenceError(std::string message) {
  return {ErrorCode::kInvalidSequence, std::move(message)};
}
Status MismatchError(std::string message) { return {ErrorCode::kMismatch, std::move(message)}; }
Status UnsupportedError(std::string message) {
  return {ErrorCode::kUnsupported, std::move(message)};
}
Status CorruptStreamError(std::string message) {
  return {ErrorCode::kCorruptStream, std::move(message)};
}
Status TruncatedStreamError(std::string message) {
  return {ErrorCode::kTruncatedStream, std::move(message)};
}
Status NumericalFailureError(std::string message) {
  return {ErrorCode::kNumericalFailure, std::move(message)};
}
Status NotFoundError(std::string message) { return {ErrorCode::kNotFound, std::move(message)}; }
Status InternalError(std::string message) { return {ErrorCode::kInternal, std::move(message)}; }
Status ResourceLimitError(std::string message) {
  return {ErrorCode::kResourceLimit, std::move(message)};
}

}  // namespace dmc

// How dmc failures reach Python: every non-OK dmc::Status becomes a `dmc.Error` whose `code` is the
// pinned dmc.ErrorCode (same integer as dmc::ErrorCode) and whose `message` is the Status message.
//
// C++ code in the bindings throws StatusError (possibly while the GIL is released); the translator
// installed by RegisterErrors turns it into a dmc.Error once the GIL is held again. Nothing else
// is translated: a TypeError from pybind11's own argument conversion stays a TypeError.
#pragma once

#include <pybind11/pybind11.h>

#include <exception>
#include <string>
#include <utility>

#include "dmc/status.h"

namespace dmc::python {

namespace py = pybind11;

// Carries a non-OK Status across the binding code to the exception translator.
class StatusError : public std::exception {
 public:
  explicit StatusError(Status status)
      : status_(std::move(status)), description_(status_.ToString()) {}
  const Status& status() const { return status_; }
  const char* what() const noexcept override { return description_.c_str(); }

 private:
  Status status_;
  std::string description_;
};

// Throws StatusError for a non-OK status. Safe to call without the GIL.
inline void ThrowIfError(const Status& status) {
  if (!status.ok()) throw StatusError(status);
}

// The value of `result`, or throws its error. Safe to call without the GIL.
template <typename T>
T ValueOrThrow(StatusOr<T>&& result) {
  if (!result.ok()) throw StatusError(result.status());
  return std::move(result).value();
}

// Shorthand for the bindings' own argument checks: throws kInvalidArgument with `message`.
[[noreturn]] inline void ThrowInvalidArgument(std::string message) {
  throw StatusError(InvalidArgumentError(std::move(message)));
}

}  // namespace dmc::python

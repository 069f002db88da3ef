#include "errors.h"

#include <pybind11/eval.h>

#include <algorithm>
#include <cctype>

#include "bindings.h"

namespace dmc::python {
namespace {

// The highest pinned code; dmc::ErrorCode values are dense from 0 to here (wire_ids.h freezes
// them), so the Python enum is built by counting.
constexpr int kLastErrorCode = static_cast<int>(ErrorCode::kResourceLimit);

// dmc.Error is a Python class (so it pickles, prints and subclasses like any exception); the
// translator below only instantiates it.
constexpr const char* kErrorClassSource = R"(
class Error(Exception):
    """A dmc call failed.

    Attributes:
        code: the dmc.ErrorCode of the failure. Its integer value is pinned (never renumbered) and
            is the one the dmc CLI reports, exiting with 10 + code.
        code_name: the code's stable lower-case name, e.g. "invalid-argument".
        message: what is at fault (file, frame, vertex, argument), as the C++ library says it.

    str(error) is "<code_name>: <message>", the dmc CLI's wording. A raised error is an instance of
    the subclass for its code, which also derives from the matching built-in exception, so code
    that catches ValueError or OSError catches dmc's too: InvalidArgumentError (ValueError: bad
    argument, invalid sequence, mismatched inputs), NotFoundError (LookupError: unknown name),
    IoError (OSError: a file cannot be read or written), ParseError and StreamError (ValueError:
    a malformed file, a corrupt or truncated stream), UnsupportedError (NotImplementedError),
    NumericalError (ArithmeticError), ResourceLimitError (MemoryError), InternalError
    (RuntimeError). dmc.Error(code, message) builds the right subclass.
    """

    def __new__(cls, code, message):
        if cls is Error:
            cls = _SUBCLASS_OF_CODE.get(int(code), Error)
        # The __new__ CPython deems safe for the class's layout: OSError's for IoError.
        return (OSError if issubclass(cls, OSError) else Exception).__new__(cls)

    def __init__(self, code, message):
        code = ErrorCode(code)
        # The built-in base gets the message alone (OSError would take the code for an errno).
        Exception.__init__(self, message)
        self.code = code
        self.message = message

    def __reduce__(self):
        return (Error, (int(self.code), self.message))

    @property
    def code_name(self):
        return _CODE_NAMES[int(self.code)]

    def __str__(self):
        return f"{self.code_name}: {self.message}"


class InvalidArgumentError(Error, ValueError):
    """Bad argument, invalid sequence or mismatched inputs (INVALID_ARGUMENT, INVALID_SEQUENCE, MISMATCH)."""


class NotFoundError(Error, LookupError):
    """An unknown operator, method or generator name (NOT_FOUND)."""


class IoError(Error, OSError):
    """A file cannot be opened, read, written or renamed (IO_ERROR)."""


class ParseError(Error, ValueError):
    """A file's syntax is malformed (PARSE_ERROR)."""


class StreamError(Error, ValueError):
    """A .dmc stream is corrupt or truncated (CORRUPT_STREAM, TRUNCATED_STREAM)."""


class UnsupportedError(Error, NotImplementedError):
    """A well-formed request this build or format version cannot do (UNSUPPORTED)."""


class NumericalError(Error, ArithmeticError):
    """A factorisation or solve failed (NUMERICAL_FAILURE)."""


class ResourceLimitError(Error, MemoryError):
    """The work or memory a request needs exceeds a limit (RESOURCE_LIMIT)."""


class InternalError(Error, RuntimeError):
    """A broken internal invariant: a bug in dmc (INTERNAL)."""


_SUBCLASS_OF_CODE = {
    int(ErrorCode.INVALID_ARGUMENT): InvalidArgumentError,
    int(ErrorCode.INVALID_SEQUENCE): InvalidArgumentError,
    int(ErrorCode.MISMATCH): InvalidArgumentError,
    int(ErrorCode.NOT_FOUND): NotFoundError,
    int(ErrorCode.IO_ERROR): IoError,
    int(ErrorCode.PARSE_ERROR): ParseError,
    int(ErrorCode.CORRUPT_STREAM): StreamError,
    int(ErrorCode.TRUNCATED_STREAM): StreamError,
    int(ErrorCode.UNSUPPORTED): UnsupportedError,
    int(ErrorCode.NUMERICAL_FAILURE): NumericalError,
    int(ErrorCode.RESOURCE_LIMIT): ResourceLimitError,
    int(ErrorCode.INTERNAL): InternalError,
}
ERROR_CLASSES = sorted(set(_SUBCLASS_OF_CODE.values()), key=lambda c: c.__name__)
)";

// Owned by the module (kept alive by its attribute); a borrowed handle is enough here and avoids
// a destructor running after the interpreter has finalised.
py::handle g_error_class;

// "invalid-argument" -> "INVALID_ARGUMENT".
std::string EnumMemberName(std::string_view code_name) {
  std::string name(code_name);
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) {
    return c == '-' ? '_' : static_cast<char>(std::toupper(c));
  });
  return name;
}

}  // namespace

void RegisterErrors(py::module_& module) {
  py::list members;
  py::dict code_names;
  for (int value = 0; value <= kLastErrorCode; ++value) {
    const std::string_view name = ErrorCodeName(static_cast<ErrorCode>(value));
    members.append(py::make_tuple(EnumMemberName(name), value));
    code_names[py::int_(value)] = py::str(std::string(name));
  }
  py::object int_enum = py::module_::import("enum").attr("IntEnum");
  py::object error_code = int_enum("ErrorCode", members, py::arg("module") = "dmc");
  error_code.attr("__doc__") =
      "Pinned dmc error codes (dmc/status.h). Values never change; the dmc CLI exits with "
      "10 + code.";

  py::dict scope;
  scope["__builtins__"] = py::module_::import("builtins");
  scope["__name__"] = "dmc";
  scope["ErrorCode"] = error_code;
  scope["_CODE_NAMES"] = code_names;
  py::exec(kErrorClassSource, scope);

  module.attr("ErrorCode") = error_code;
  module.attr("Error") = scope["Error"];
  for (const py::handle subclass : scope["ERROR_CLASSES"]) {
    module.attr(subclass.attr("__name__")) = subclass;
  }
  g_error_class = module.attr("Error");

  py::register_exception_translator([](std::exception_ptr pending) {
    try {
      if (pending) std::rethrow_exception(pending);
    } catch (const StatusError& error) {
      // dmc.Error(code, message) is the code's subclass.
      py::object instance =
          g_error_class(static_cast<int>(error.status().code()), error.status().message());
      PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(instance.ptr())), instance.ptr());
    }
  });
}

}  // namespace dmc::python

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

    str(error) is "<code_name>: <message>", the dmc CLI's wording.
    """

    def __init__(self, code, message):
        code = ErrorCode(code)
        super().__init__(code, message)
        self.code = code
        self.message = message

    @property
    def code_name(self):
        return _CODE_NAMES[int(self.code)]

    def __str__(self):
        return f"{self.code_name}: {self.message}"
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
  g_error_class = module.attr("Error");

  py::register_exception_translator([](std::exception_ptr pending) {
    try {
      if (pending) std::rethrow_exception(pending);
    } catch (const StatusError& error) {
      py::object instance =
          g_error_class(static_cast<int>(error.status().code()), error.status().message());
      PyErr_SetObject(g_error_class.ptr(), instance.ptr());
    }
  });
}

}  // namespace dmc::python

// Registration functions of the dmc Python module, one per group of bindings; module.cpp calls
// them in this order (errors first: every other group raises dmc.Error).
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <string_view>

namespace dmc::python {

namespace py = pybind11;

// dmc.ErrorCode (an IntEnum, one member per dmc::ErrorCode: ErrorCode.INVALID_ARGUMENT == 1),
// dmc.Error, and the translator from StatusError to dmc.Error (errors.cpp).
void RegisterErrors(py::module_& module);
void RegisterCodec(py::module_& module);  // encode, decode, info (codec_bindings.cpp)
void RegisterAnalysis(
    py::module_& module);                // metrics, laplacian, operators (analysis_bindings.cpp)
void RegisterEdit(py::module_& module);  // edit, methods (edit_bindings.cpp)
void RegisterIo(py::module_& module);    // read_sequence, write_sequence, synth (io_bindings.cpp)

// `doc` with its signature first as CPython's text signature, "name(params)\n--\n\n" + doc, from
// which inspect.signature() and help() read the parameters of a builtin (pybind11's generated
// signature line is disabled: it would only say "handle"). `doc` must start with "name(params)",
// valid Python parameters, optionally followed by " -> result" (module.cpp).
std::string WithTextSignature(std::string_view doc);
// The docstring after its first line (the signature line, which the caller rebuilds).
inline std::string AfterFirstLine(std::string_view doc) {
  const size_t end = doc.find('\n');
  return end == std::string_view::npos ? std::string() : std::string(doc.substr(end));
}
// Python's repr() of a C++ default, for the parameters of a signature built from the defaults.
template <typename T>
std::string Repr(const T& value) {
  return std::string(py::repr(py::cast(value)));
}

}  // namespace dmc::python

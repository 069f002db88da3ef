// Registration functions of the dmc Python module, one per group of bindings; module.cpp calls
// them in this order (errors first: every other group raises dmc.Error).
#pragma once

#include <pybind11/pybind11.h>

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

}  // namespace dmc::python

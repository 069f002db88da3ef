// Conversions between NumPy arrays and dmc's C++ types.
//
// Input contract (every function taking frames and faces):
//  - frames: anything numpy.asarray accepts, shape (F, V, 3) or (V, 3) (one frame), of a real
//    floating or integer dtype. float32 C-contiguous input is copied once into the MeshSequence
//    (which owns its storage); any other dtype or layout is converted to float32 on the way (so
//    float64 works, and a value beyond float32's range becomes infinite and is then refused by
//    ValidateSequence as non-finite).
//  - faces: shape (T, 3) of an integer dtype; values must fit int32 (checked, never wrapped).
//  - Shape, dtype and range problems raise dmc.Error(INVALID_ARGUMENT) naming the argument and the
//    shape or dtype received. Model violations (indices out of range, NaN, no triangles) are
//    found later by ValidateSequence (INVALID_SEQUENCE) and name the frame, vertex or triangle.
//
// Output contract: arrays returned to Python view memory owned by a capsule holding the C++ object
// they came from (no copy); they are writable and independent of any other call's results.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/SparseCore>
#include <string_view>

#include "dmc/sequence.h"

namespace dmc::python {

namespace py = pybind11;

// Builds a MeshSequence from frames and faces (see the contract above). Needs the GIL. Does NOT
// run ValidateSequence: callers do that after releasing the GIL (see ValidateOrThrow).
// `frames_name` names the frames argument in error messages ("frames", "original", ...).
MeshSequence SequenceFromArrays(const py::handle& frames, const py::handle& faces,
                                std::string_view frames_name = "frames");

// Runs ValidateSequence and throws its error. Safe without the GIL.
void ValidateOrThrow(const MeshSequence& sequence);

// (frames float32 (F, V, 3), faces int32 (T, 3)) viewing `sequence`, which the arrays keep
// alive.
py::tuple SequenceToArrays(MeshSequence&& sequence);

// A row-major copy of `matrix` whose CSR arrays (data float64, indices int32, indptr int32) view
// it without a further copy; returned as that (data, indices, indptr) triple.
py::tuple CsrArrays(const Eigen::SparseMatrix<double>& matrix);

// A float64 1-D array holding `values` (copied).
py::array_t<double> VectorToArray(const Eigen::VectorXd& values);

}  // namespace dmc::python

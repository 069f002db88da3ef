// The `dmc` Python module: the dynamic mesh codec, its metrics, Laplace operators and sequence I/O
// on NumPy arrays.
#include <pybind11/pybind11.h>

#include "bindings.h"

PYBIND11_MODULE(dmc, module) {
  module.doc() = R"(dmc: dynamic mesh codec (animated triangle meshes with fixed connectivity).

Meshes are NumPy arrays: frames float32 of shape (F, V, 3) (frames x vertices x xyz; a (V, 3)
array is one frame) and faces int32 of shape (T, 3) (0-based vertex indices, shared by every
frame). Other real dtypes are converted (float64 -> float32); wrong shapes or dtypes raise
dmc.Error with code ErrorCode.INVALID_ARGUMENT.

Functions: encode, decode, info (the codec); metrics, laplacian, operators (analysis); edit,
methods (Laplacian processing); read_sequence, write_sequence, synth, synth_names (sequences). Every failure raises dmc.Error, whose code is the
pinned dmc.ErrorCode. Long calls release the GIL, so threads can run them in parallel.)";
  module.attr("__version__") = DMC_VERSION_STRING;
  // Every docstring starts with a hand-written signature ("encode(frames, faces, *, ...)") that
  // names the accepted array forms; pybind11's generated one would only say "handle".
  pybind11::options options;
  options.disable_function_signatures();
  dmc::python::RegisterErrors(module);
  dmc::python::RegisterCodec(module);
  dmc::python::RegisterAnalysis(module);
  dmc::python::RegisterEdit(module);
  dmc::python::RegisterIo(module);
}

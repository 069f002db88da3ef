// The `dmc` Python module: the dynamic mesh codec, its metrics, Laplace operators and sequence I/O
// on NumPy arrays.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "dmc/simd.h"
#include "dmc/version.h"
#include "errors.h"

namespace dmc::python {

std::string WithTextSignature(std::string_view doc) {
  // The parameters end at the parenthesis that closes the first one (defaults may hold strings
  // with parentheses: skip quoted text).
  int depth = 0;
  char quote = 0;
  for (size_t i = 0; i < doc.size() && doc[i] != '\n'; ++i) {
    const char c = doc[i];
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '(') {
      ++depth;
    } else if (c == ')' && --depth == 0) {
      return std::string(doc.substr(0, i + 1)) + "\n--\n\n" + std::string(doc);
    }
  }
  return std::string(doc);  // no signature: the docstring as it is
}

}  // namespace dmc::python

// The extension module of the dmc package (python/dmc/__init__.py re-exports it).
PYBIND11_MODULE(_dmc, module) {
  module.doc() = R"(dmc: dynamic mesh codec (animated triangle meshes with fixed connectivity).

Meshes are NumPy arrays: frames float32 of shape (F, V, 3) (frames x vertices x xyz; a (V, 3)
array is one frame) and faces int32 of shape (T, 3) (0-based vertex indices, shared by every
frame). Other real dtypes are converted (float64 -> float32); wrong shapes or dtypes raise
dmc.Error with code ErrorCode.INVALID_ARGUMENT.

Functions: encode, decode, info (the codec); metrics, laplacian, operators (analysis); edit,
methods (Laplacian processing); read_sequence, write_sequence, synth, synth_names (sequences);
simd_variants, simd_variant, set_simd_variant (the SIMD variant of frame synthesis; the DMC_SIMD
environment variable sets it at import). Every failure raises dmc.Error, whose code is the
pinned dmc.ErrorCode. Long calls release the GIL, so threads can run them in parallel.)";
  module.attr("__version__") = dmc::LibraryVersionString();
  // Every docstring starts with a hand-written signature ("encode(frames, faces, *, ...)") that
  // names the accepted array forms; pybind11's generated one would only say "handle".
  pybind11::options options;
  options.disable_function_signatures();
  dmc::python::RegisterErrors(module);
  dmc::python::RegisterCodec(module);
  dmc::python::RegisterAnalysis(module);
  dmc::python::RegisterEdit(module);
  dmc::python::RegisterIo(module);

  // Frame synthesis's SIMD variants (dmc/simd.h): the same output from each, different speed.
  dmc::python::ThrowIfError(dmc::SetSimdVariantFromEnvironment());
  using dmc::python::WithTextSignature;
  module.def("simd_variants", &dmc::SupportedSimdVariants,
             WithTextSignature("simd_variants() -> list[str]\n\nThe SIMD variants this CPU runs, "
                               "fastest first (\"baseline\" last).")
                 .c_str());
  module.def(
      "simd_variant", &dmc::ActiveSimdVariant,
      WithTextSignature("simd_variant() -> str\n\nThe SIMD variant frame synthesis runs now.")
          .c_str());
  module.def(
      "set_simd_variant",
      [](const std::string& name) { dmc::python::ThrowIfError(dmc::SetSimdVariant(name)); },
      pybind11::arg("name"),
      WithTextSignature(
          "set_simd_variant(name)\n\nForces a SIMD variant for the whole process (\"auto\": the "
          "fastest); raises dmc.Error (INVALID_ARGUMENT for an unknown name, UNSUPPORTED for one "
          "this CPU lacks).")
          .c_str());
}

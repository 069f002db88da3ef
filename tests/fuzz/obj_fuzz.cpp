// Fuzz target: the strict OBJ parser. A result's triangles must index its vertices.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.h"
#include "io/mesh_formats.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto mesh = dmc::io_internal::ParseObj(text);
  if (mesh.ok()) dmc::fuzz::CheckParsedMesh(*mesh);
  return 0;
}

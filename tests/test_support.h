// Helpers shared by the test suites: tiny meshes and access to ../shared/data.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "dmc/sequence.h"
#include "synth/grid_triangles.h"

// 1 when a sanitizer replaces the allocator (tools/sanitize.sh, tools/fuzz.sh): heap and RSS
// figures then include its quarantine and shadow memory, so tests measure them unsanitized only.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define DMC_SANITIZER_OWNS_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer)
#define DMC_SANITIZER_OWNS_ALLOCATOR 1
#endif
#endif
#ifndef DMC_SANITIZER_OWNS_ALLOCATOR
#define DMC_SANITIZER_OWNS_ALLOCATOR 0
#endif

namespace dmc::testing {

// Path of a sequence under ../shared/data, or an empty path when the data is absent (tests then
// GTEST_SKIP, so a checkout without ../shared still passes).
inline std::filesystem::path SharedData(const std::string& relative) {
  const std::filesystem::path path = std::filesystem::path(DMC_SHARED_DATA_DIR) / relative;
  return std::filesystem::exists(path) ? path : std::filesystem::path();
}

#define DMC_REQUIRE_SHARED_DATA(var, relative)                            \
  const std::filesystem::path var = ::dmc::testing::SharedData(relative); \
  if (var.empty()) GTEST_SKIP() << "../shared/data/" << (relative) << " is absent"

// A regular tetrahedron-like closed mesh (4 vertices, 4 triangles, outward orientation).
inline MeshSequence Tetrahedron(int frames = 1) {
  Triangles tris(4, 3);
  tris << 0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2;
  MeshSequence seq(4, tris, frames);
  for (int f = 0; f < frames; ++f) {
    seq.frame(f) << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    seq.frame(f).col(0).array() += 0.1f * static_cast<float>(f);
  }
  return seq;
}

// An n×n vertex grid in the z = 0 plane on [0,1]², two triangles per cell.
inline MeshSequence PlanarGrid(int n, int frames = 1) {
  MeshSequence seq(n * n, synth::GridTriangles(n, n, synth::GridDiagonals::kUniform), frames);
  for (int f = 0; f < frames; ++f) {
    for (int v = 0; v < n * n; ++v) {
      seq.frame(f).row(v) << static_cast<float>(v % n) / static_cast<float>(n - 1),
          static_cast<float>(v / n) / static_cast<float>(n - 1), 0.0f;
    }
  }
  return seq;
}

}  // namespace dmc::testing

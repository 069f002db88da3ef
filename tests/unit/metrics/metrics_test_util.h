// Small builders shared by the metrics tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "dmc/sequence.h"

namespace dmc::testing {

using Frame = std::vector<std::array<float, 3>>;

// A sequence with the given triangles and frames (every frame must list the same vertex count).
inline MeshSequence MakeSequence(const std::vector<std::array<int32_t, 3>>& triangles,
                                 const std::vector<Frame>& frames) {
  Triangles tris(static_cast<Eigen::Index>(triangles.size()), 3);
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) tris(static_cast<Eigen::Index>(t), k) = triangles[t][k];
  }
  const int vertex_count = frames.empty() ? 0 : static_cast<int>(frames.front().size());
  MeshSequence sequence(vertex_count, tris, static_cast<int>(frames.size()));
  for (size_t f = 0; f < frames.size(); ++f) {
    for (int v = 0; v < vertex_count; ++v) {
      for (int k = 0; k < 3; ++k) sequence.frame(static_cast<int>(f))(v, k) = frames[f][v][k];
    }
  }
  return sequence;
}

// `frame` moved by `offset`.
inline Frame Translated(const Frame& frame, const std::array<float, 3>& offset) {
  Frame moved = frame;
  for (auto& p : moved) {
    for (int k = 0; k < 3; ++k) p[k] += offset[k];
  }
  return moved;
}

// Tolerance for values computed along different (but equivalent) arithmetic paths: `relative`
// times the value's magnitude, and never below `relative` itself (values under 1 get an absolute
// tolerance, so exact zeros can be compared too).
inline double RelativeTolerance(double expected, double relative = 1e-12) {
  return relative * std::max(1.0, std::abs(expected));
}

}  // namespace dmc::testing

// Seam welding of a glTF import: vertices whose trajectories coincide in every frame (the copies
// a glTF exporter makes along UV and normal seams) become one.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "io/gltf_import_internal.h"

namespace dmc::io_internal::gltf {
namespace {

// Welds vertices whose trajectories coincide within `tolerance` in every frame. Returns the map
// old vertex -> new vertex (new vertices numbered by first occurrence).
std::vector<int32_t> WeldMap(const MeshSequence& sequence, double tolerance) {
  const int vertex_count = sequence.vertex_count();
  const auto frame0 = sequence.frame(0);
  std::vector<int32_t> by_x(static_cast<size_t>(vertex_count));
  std::iota(by_x.begin(), by_x.end(), 0);
  std::sort(by_x.begin(), by_x.end(), [&](int32_t a, int32_t b) {
    return frame0(a, 0) < frame0(b, 0) || (frame0(a, 0) == frame0(b, 0) && a < b);
  });
  // root[v] == v for a group's first-swept vertex; every other member points straight at it.
  std::vector<int32_t> root(static_cast<size_t>(vertex_count));
  std::iota(root.begin(), root.end(), 0);
  auto same_trajectory = [&](int a, int b) {
    for (int f = 0; f < sequence.frame_count(); ++f) {
      const auto frame = sequence.frame(f);
      for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(static_cast<double>(frame(a, axis)) - frame(b, axis)) > tolerance) {
          return false;
        }
      }
    }
    return true;
  };
  // Sweep in x order: a vertex's candidates lie within `tolerance` of it in x.
  for (size_t i = 0; i < by_x.size(); ++i) {
    const int v = by_x[i];
    for (size_t j = i; j-- > 0;) {
      const int u = by_x[j];
      if (static_cast<double>(frame0(v, 0)) - frame0(u, 0) > tolerance) break;
      if (root[static_cast<size_t>(u)] == u && same_trajectory(u, v)) {
        root[static_cast<size_t>(v)] = u;
        break;
      }
    }
  }
  // New indices by first occurrence in file order.
  std::vector<int32_t> map(static_cast<size_t>(vertex_count), -1);
  std::vector<int32_t> group_index(static_cast<size_t>(vertex_count), -1);
  int32_t next = 0;
  for (int v = 0; v < vertex_count; ++v) {
    int32_t& index = group_index[static_cast<size_t>(root[static_cast<size_t>(v)])];
    if (index < 0) index = next++;
    map[static_cast<size_t>(v)] = index;
  }
  return map;
}

}  // namespace

Status WeldImport(GltfImport& result, const std::vector<int32_t>& triangles) {
  const MeshSequence& sequence = result.sequence;
  const int vertex_total = sequence.vertex_count();
  const int frame_count = sequence.frame_count();
  const double tolerance = 1e-6 * ComputeBoundingBox(sequence).diagonal();
  result.vertex_map = WeldMap(sequence, tolerance);
  const int welded_count =
      vertex_total == 0 ? 0
                        : *std::max_element(result.vertex_map.begin(), result.vertex_map.end()) + 1;
  std::vector<int32_t> kept;
  int collapsed = 0;
  for (size_t t = 0; t < triangles.size(); t += 3) {
    const int32_t a = result.vertex_map[static_cast<size_t>(triangles[t])];
    const int32_t b = result.vertex_map[static_cast<size_t>(triangles[t + 1])];
    const int32_t c = result.vertex_map[static_cast<size_t>(triangles[t + 2])];
    if (a == b || b == c || a == c) {
      ++collapsed;
      continue;
    }
    kept.insert(kept.end(), {a, b, c});
  }
  if (kept.empty()) return UnsupportedError("welding collapsed every triangle");
  MeshSequence welded(welded_count, ToTriangles(kept), frame_count);
  welded.frame_rate = sequence.frame_rate;
  for (int f = 0; f < frame_count; ++f) {
    auto source = sequence.frame(f);
    auto target = welded.frame(f);
    for (int v = 0; v < vertex_total; ++v)
      target.row(result.vertex_map[static_cast<size_t>(v)]) = source.row(v);
  }
  result.warnings.push_back(
      "welded " + std::to_string(vertex_total) + " vertices into " + std::to_string(welded_count) +
      (collapsed ? ", dropping " + std::to_string(collapsed) + " triangle(s) that collapsed"
                 : std::string()));
  result.sequence = std::move(welded);
  return Status::Ok();
}

}  // namespace dmc::io_internal::gltf

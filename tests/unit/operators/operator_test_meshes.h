// Synthetic meshes for the operator and fitting tests: irregular planar grids, icospheres,
// strips, degenerate and multi-component meshes, and smooth animations of them.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/topology.h"
#include "synth/grid_triangles.h"
#include "test_support.h"

namespace dmc::testing {

// An n×n grid on [0,1]² (z = 0) whose interior vertices are moved by up to `jitter` cells in x
// and y (jitter < 0.5 keeps every triangle positively oriented), diagonals alternating so that
// valences vary between 4 and 8.
inline MeshSequence JitteredPlanarGrid(int n, double jitter, unsigned seed = 7) {
  MeshSequence seq(n * n, synth::GridTriangles(n, n, synth::GridDiagonals::kAlternating), 1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-jitter, jitter);
  const double h = 1.0 / (n - 1);
  for (int v = 0; v < n * n; ++v) {
    const int x = v % n, y = v / n;
    const bool interior = x > 0 && y > 0 && x + 1 < n && y + 1 < n;
    const double dx = interior ? offset(rng) * h : 0.0, dy = interior ? offset(rng) * h : 0.0;
    seq.frame(0).row(v) << static_cast<float>(x * h + dx), static_cast<float>(y * h + dy), 0.0f;
  }
  return seq;
}

// Geodesic sphere: an icosahedron subdivided `level` times, vertices projected to `radius`.
inline MeshSequence Icosphere(int level, double radius = 1.0) {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> points = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                                         {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                                         {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  std::vector<std::array<int, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& q : points) q.normalize();
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      points.push_back((points[a] + points[b]).normalized());
      midpoint[key] = static_cast<int>(points.size()) - 1;
      return static_cast<int>(points.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : faces) {
      const int ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    faces = std::move(next);
  }
  Triangles tris(static_cast<int>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) {
    tris.row(static_cast<int>(f)) << faces[f][0], faces[f][1], faces[f][2];
  }
  MeshSequence seq(static_cast<int>(points.size()), tris, 1);
  for (size_t v = 0; v < points.size(); ++v) {
    seq.frame(0).row(static_cast<int>(v)) = (radius * points[v]).cast<float>().transpose();
  }
  return seq;
}

// A strip of 2×n vertices and 2(n−1) triangles (every vertex on the boundary, corners of
// degree 2), bent along a gentle arc so that it is not planar.
inline MeshSequence Strip(int n) {
  Triangles tris(2 * (n - 1), 3);
  for (int k = 0; k + 1 < n; ++k) {
    tris.row(2 * k) << 2 * k, 2 * k + 2, 2 * k + 1;
    tris.row(2 * k + 1) << 2 * k + 1, 2 * k + 2, 2 * k + 3;
  }
  MeshSequence seq(2 * n, tris, 1);
  for (int k = 0; k < n; ++k) {
    const double angle = 0.15 * k;
    for (int side = 0; side < 2; ++side) {
      seq.frame(0).row(2 * k + side) << static_cast<float>(std::sin(angle)),
          static_cast<float>(side == 0 ? 0.0 : 0.3 + 0.05 * k),
          static_cast<float>(1.0 - std::cos(angle));
    }
  }
  return seq;
}

// Two disjoint tetrahedra plus one isolated vertex (index 8): several components.
inline MeshSequence TwoTetrahedraAndIsolatedVertex() {
  Triangles tris(8, 3);
  tris << 0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2,  //
      4, 6, 5, 4, 5, 7, 5, 6, 7, 4, 7, 6;
  MeshSequence seq(9, tris, 1);
  seq.frame(0) << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1,  //
      3, 0, 0, 4.5, 0.2, 0, 3.1, 1.3, 0, 3.2, 0.1, 1.1, 9, 9, 9;
  return seq;
}

// A grid with defects: one vertex collapsed onto its neighbour (zero-area triangles and a
// zero-length edge), one pushed nearly onto the opposite edge (a 179.9° angle), and a sliver.
inline MeshSequence DefectiveGrid(int n = 8) {
  MeshSequence seq = PlanarGrid(n);
  auto frame = seq.frame(0);
  frame.row(n + 2) = frame.row(n + 1);  // coincident vertices
  const int v = 3 * n + 3;
  frame.row(v) = frame.row(v + 1) * 0.5f + frame.row(v - 1) * 0.5f;  // collinear with neighbours
  frame(v, 1) += 1e-5f;
  frame(5 * n + 5, 0) += 0.45f / static_cast<float>(n - 1);  // long thin triangles
  return seq;
}

// Smooth, non-rigid motion of a mesh: per-frame bend, twist, scale and translation of frame 0,
// so the trajectories have a rich but structured span.
inline MeshSequence Animate(const MeshSequence& base, int frames, double amount = 0.3) {
  MeshSequence seq(base.vertex_count(), base.triangles(), frames);
  const auto rest = base.frame(0);
  for (int f = 0; f < frames; ++f) {
    const double t = static_cast<double>(f) / std::max(1, frames - 1);
    for (int v = 0; v < base.vertex_count(); ++v) {
      const double x = rest(v, 0), y = rest(v, 1), z = rest(v, 2);
      const double bend = amount * std::sin(3.0 * t + 1.0) * x * x;
      const double twist = amount * std::cos(2.0 * t) * y;
      const double scale = 1.0 + 0.2 * amount * std::sin(5.0 * t) * z;
      const double nx = (x * std::cos(twist) - z * std::sin(twist)) * scale + 0.5 * t;
      const double nz = x * std::sin(twist) + z * std::cos(twist) + bend;
      const double ny = y * scale + 0.1 * amount * std::sin(4.0 * t + 3.0 * x);
      seq.frame(f).row(v) << static_cast<float>(nx), static_cast<float>(ny), static_cast<float>(nz);
    }
  }
  return seq;
}

}  // namespace dmc::testing

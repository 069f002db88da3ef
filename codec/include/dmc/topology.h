// Mesh topology derived from a triangle list: unique edges, one-rings, boundary, components.
//
// Contract:
//  - Edges are the unique undirected edges of the triangle list, each stored once as (i, j) with
//    i < j, sorted lexicographically. Edge order is deterministic and shared by every module that
//    indexes per-edge data (operator weights, STED, the DDL weight coder).
//  - One-rings are in CSR form: the neighbours of v are ring_neighbors[ring_offsets[v] ..
//    ring_offsets[v+1]), sorted ascending, with ring_edges giving the matching edge index.
//  - Vertices referenced by no triangle are isolated: empty one-ring, their own component.
//  - Input must already be valid (indices in range); BuildTopology does not re-check.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dmc/sequence.h"

namespace dmc {

struct MeshTopology {
  int vertex_count = 0;
  std::vector<std::array<int32_t, 2>> edges;  // (i, j), i < j, sorted
  // For each edge, the opposite vertex in up to two incident triangles (-1 when absent).
  // Edges with more than two incident triangles are non-manifold; only the first two are kept.
  std::vector<std::array<int32_t, 2>> edge_opposite;
  std::vector<int32_t> edge_face_count;  // incident triangles per edge

  std::vector<int32_t> ring_offsets;    // size V + 1
  std::vector<int32_t> ring_neighbors;  // size 2E
  std::vector<int32_t> ring_edges;      // size 2E, edge index of (v, neighbour)

  std::vector<int32_t> component_of_vertex;  // component id per vertex, ids 0..components-1
  int component_count = 0;
  int isolated_vertex_count = 0;

  int boundary_edge_count = 0;
  int boundary_loop_count = 0;
  int non_manifold_edge_count = 0;
  std::vector<uint8_t> vertex_on_boundary;  // 1 if the vertex touches a boundary edge

  int edge_count() const { return static_cast<int>(edges.size()); }
  int degree(int v) const { return ring_offsets[v + 1] - ring_offsets[v]; }
  bool is_manifold() const { return non_manifold_edge_count == 0; }
  bool is_boundary_vertex(int v) const { return vertex_on_boundary[v] != 0; }
  // Euler characteristic V - E + T over referenced vertices.
  int euler_characteristic = 0;
};

MeshTopology BuildTopology(const Triangles& triangles, int vertex_count);

}  // namespace dmc

#include "dmc/topology.h"

#include <algorithm>
#include <numeric>

namespace dmc {
namespace {

// Union-find with path halving; small and only used here.
class DisjointSets {
 public:
  explicit DisjointSets(int n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int Find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Unite(int a, int b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

// The undirected edges, each with its opposite vertices and face count, sorted by (i, j).
void BuildEdges(const Triangles& triangles, MeshTopology& topo) {
  const int t_count = static_cast<int>(triangles.rows());
  // Half-edge records (min, max, opposite vertex), sorted to group each undirected edge.
  struct HalfEdge {
    int32_t a, b, opposite;
  };
  std::vector<HalfEdge> half_edges;
  half_edges.reserve(static_cast<size_t>(t_count) * 3);
  for (int t = 0; t < t_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      const int32_t i = triangles(t, k), j = triangles(t, (k + 1) % 3),
                    o = triangles(t, (k + 2) % 3);
      if (i == j) continue;  // degenerate side: not an edge
      half_edges.push_back({std::min(i, j), std::max(i, j), o});
    }
  }
  std::sort(half_edges.begin(), half_edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : x.opposite < y.opposite);
  });
  for (size_t h = 0; h < half_edges.size();) {
    size_t end = h;
    while (end < half_edges.size() && half_edges[end].a == half_edges[h].a &&
           half_edges[end].b == half_edges[h].b) {
      ++end;
    }
    const int count = static_cast<int>(end - h);
    topo.edges.push_back({half_edges[h].a, half_edges[h].b});
    topo.edge_opposite.push_back(
        {half_edges[h].opposite, count > 1 ? half_edges[h + 1].opposite : -1});
    topo.edge_face_count.push_back(count);
    h = end;
  }
}

// One-rings in CSR form, each ring sorted ascending.
void BuildRings(MeshTopology& topo) {
  const int e_count = topo.edge_count();
  topo.ring_offsets.assign(topo.vertex_count + 1, 0);
  for (const auto& e : topo.edges) {
    ++topo.ring_offsets[e[0] + 1];
    ++topo.ring_offsets[e[1] + 1];
  }
  std::partial_sum(topo.ring_offsets.begin(), topo.ring_offsets.end(), topo.ring_offsets.begin());
  topo.ring_neighbors.resize(2 * static_cast<size_t>(e_count));
  topo.ring_edges.resize(2 * static_cast<size_t>(e_count));
  std::vector<int32_t> cursor(topo.ring_offsets.begin(), topo.ring_offsets.end() - 1);
  // Edges are sorted by (i, j): appending in edge order keeps every ring sorted ascending, since
  // a vertex's smaller neighbours come from edges (k, v), k < v, which precede edges (v, j).
  for (int e = 0; e < e_count; ++e) {
    const int i = topo.edges[e][0], j = topo.edges[e][1];
    topo.ring_neighbors[cursor[j]] = i;
    topo.ring_edges[cursor[j]++] = e;
  }
  for (int e = 0; e < e_count; ++e) {
    const int i = topo.edges[e][0], j = topo.edges[e][1];
    topo.ring_neighbors[cursor[i]] = j;
    topo.ring_edges[cursor[i]++] = e;
  }
}

// Components (isolated vertices count as their own component).
void FindComponents(MeshTopology& topo) {
  const int vertex_count = topo.vertex_count;
  DisjointSets vertex_sets(vertex_count);
  for (const auto& e : topo.edges) vertex_sets.Unite(e[0], e[1]);
  topo.component_of_vertex.assign(vertex_count, -1);
  std::vector<int32_t> root_to_component(vertex_count, -1);
  for (int v = 0; v < vertex_count; ++v) {
    const int root = vertex_sets.Find(v);
    if (root_to_component[root] < 0) root_to_component[root] = topo.component_count++;
    topo.component_of_vertex[v] = root_to_component[root];
    if (topo.degree(v) == 0) ++topo.isolated_vertex_count;
  }
}

// Boundary edges, vertices and loops, and non-manifold edges.
void FindBoundaries(MeshTopology& topo) {
  const int vertex_count = topo.vertex_count;
  topo.vertex_on_boundary.assign(vertex_count, 0);
  DisjointSets boundary_sets(vertex_count);
  for (int e = 0; e < topo.edge_count(); ++e) {
    const int faces = topo.edge_face_count[e];
    if (faces > 2) ++topo.non_manifold_edge_count;
    if (faces == 1) {
      ++topo.boundary_edge_count;
      topo.vertex_on_boundary[topo.edges[e][0]] = 1;
      topo.vertex_on_boundary[topo.edges[e][1]] = 1;
      boundary_sets.Unite(topo.edges[e][0], topo.edges[e][1]);
    }
  }
  for (int v = 0; v < vertex_count; ++v) {
    if (topo.vertex_on_boundary[v] && boundary_sets.Find(v) == v) ++topo.boundary_loop_count;
  }
}

}  // namespace

MeshTopology BuildTopology(const Triangles& triangles, int vertex_count) {
  MeshTopology topo;
  topo.vertex_count = vertex_count;
  BuildEdges(triangles, topo);
  BuildRings(topo);
  FindComponents(topo);
  FindBoundaries(topo);
  const int t_count = static_cast<int>(triangles.rows());
  topo.euler_characteristic =
      (vertex_count - topo.isolated_vertex_count) - topo.edge_count() + t_count;
  return topo;
}

}  // namespace dmc

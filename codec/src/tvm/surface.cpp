// Surface deformation (Section IV-C): Boltzmann smooth-minimum weights over the nearest centre and
// its most affine neighbours, dual-quaternion blending, and adaptive edge subdivision (IV-D).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "dmc/tvm.h"

namespace dmc::tvm {

void ComputeVertexWeights(const AffinityGraph& graph, int frame, const Eigen::Vector3d& vertex,
                          const SurfaceOptions& options, std::vector<int32_t>& centres,
                          std::vector<double>& weights) {
  const int k = std::max(1, std::min(options.neighbours, graph.neighbour_count()));
  const FramePositionsD& frame_centres = graph.centres().positions[static_cast<size_t>(frame)];
  const int nearest = graph.NearestCentre(frame, vertex);

  // C_k: the nearest centre, then its most affine centres. Centres with zero affinity to it (past
  // min_affinity: they are ever far apart, e.g. another body) never join, even if that leaves
  // fewer than k; the remaining slots repeat the nearest centre with weight 0.
  std::array<int32_t, 64> set_storage{};
  std::array<double, 64> distance_storage{};
  std::vector<int32_t> set_heap;
  std::vector<double> distance_heap;
  int32_t* set = set_storage.data();
  double* distance = distance_storage.data();
  if (k > 64) {
    set_heap.resize(static_cast<size_t>(k));
    distance_heap.resize(static_cast<size_t>(k));
    set = set_heap.data();
    distance = distance_heap.data();
  }
  int size = 0;
  set[size++] = nearest;
  const auto neighbours = graph.Neighbours(nearest);
  const auto affinities = graph.NeighbourAffinities(nearest);
  for (size_t j = 0; j < neighbours.size() && size < k; ++j) {
    if (neighbours[j] == nearest || affinities[j] <= 0.0) continue;
    set[size++] = neighbours[j];
  }
  for (int i = 0; i < size; ++i) {
    distance[i] = (frame_centres.row(set[i]).transpose() - vertex).norm();
  }

  // w'_i = softmax(-d_i / (sigma d_1 + eps)); shifting by d_1 keeps exp() in range and leaves the
  // softmax unchanged. At d_1 = 0 every other w'_i underflows to 0: interpolation holds exactly.
  const double epsilon = options.relative_epsilon * (graph.spacing() > 0.0 ? graph.spacing() : 1.0);
  const double nearest_distance = distance[0];
  const double temperature = options.sigma * nearest_distance + epsilon;
  double total = 0.0, smallest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < size; ++i) {
    distance[i] =
        std::exp(-(distance[i] - nearest_distance) / temperature);  // now w'_i unnormalised
    total += distance[i];
  }
  for (int i = 0; i < size; ++i) {
    distance[i] /= total;
    smallest = std::min(smallest, distance[i]);
  }
  // w_i = (w'_i - min w') / sum (w' - min w'): the farthest centre of the set gets weight 0.
  double shifted_total = 0.0;
  for (int i = 0; i < size; ++i) shifted_total += distance[i] - smallest;
  for (int i = 0; i < k; ++i) {
    centres.push_back(i < size ? set[i] : nearest);
    double weight = 0.0;
    if (i < size) {
      // One centre, or all at the same distance: nothing to prefer, so the nearest takes all.
      weight =
          shifted_total > 0.0 ? (distance[i] - smallest) / shifted_total : (i == 0 ? 1.0 : 0.0);
    }
    weights.push_back(weight);
  }
}

SurfaceWeights ComputeSurfaceWeights(const AffinityGraph& graph, int frame,
                                     const Eigen::Ref<const FramePositionsD>& positions,
                                     const SurfaceOptions& options) {
  SurfaceWeights result;
  result.k = std::max(1, std::min(options.neighbours, graph.neighbour_count()));
  const int vertices = static_cast<int>(positions.rows());
  result.centres.resize(static_cast<size_t>(vertices) * result.k);
  result.weights.resize(static_cast<size_t>(vertices) * result.k);
  tbb::parallel_for(tbb::blocked_range<int>(0, vertices, 256), [&](const auto& range) {
    std::vector<int32_t> centres;
    std::vector<double> weights;
    for (int v = range.begin(); v != range.end(); ++v) {
      centres.clear();
      weights.clear();
      ComputeVertexWeights(graph, frame, positions.row(v).transpose(), options, centres, weights);
      std::copy(centres.begin(), centres.end(),
                result.centres.begin() + static_cast<std::ptrdiff_t>(v) * result.k);
      std::copy(weights.begin(), weights.end(),
                result.weights.begin() + static_cast<std::ptrdiff_t>(v) * result.k);
    }
  });
  return result;
}

namespace {

DualQuaternion VertexTransform(std::span<const DualQuaternion> transforms, const int32_t* centres,
                               const double* weights, int k) {
  std::array<DualQuaternion, 64> local;
  std::vector<DualQuaternion> heap;
  DualQuaternion* chosen = local.data();
  if (k > 64) {
    heap.resize(static_cast<size_t>(k));
    chosen = heap.data();
  }
  for (int i = 0; i < k; ++i) chosen[i] = transforms[static_cast<size_t>(centres[i])];
  return BlendDualQuaternions({chosen, static_cast<size_t>(k)}, {weights, static_cast<size_t>(k)});
}

uint64_t EdgeKey(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

using Triangle = std::array<int32_t, 3>;

// A frame while its edges are split: rest positions, the blended transform of every vertex, and
// the triangles; vertices are only appended.
struct RefiningMesh {
  std::vector<Eigen::Vector3d> rest;
  std::vector<DualQuaternion> transforms;
  std::vector<Triangle> triangles;
};

// The frame's vertices with the transforms blended from their precomputed weights.
RefiningMesh StartRefining(const TvmFrame& frame_mesh, std::span<const DualQuaternion> transforms,
                           const SurfaceWeights& weights) {
  const int k = weights.k;
  const int vertices = frame_mesh.vertex_count();
  RefiningMesh mesh;
  mesh.transforms.resize(static_cast<size_t>(vertices));
  tbb::parallel_for(tbb::blocked_range<int>(0, vertices, 512), [&](const auto& range) {
    for (int v = range.begin(); v != range.end(); ++v) {
      const size_t at = static_cast<size_t>(v) * k;
      mesh.transforms[static_cast<size_t>(v)] =
          VertexTransform(transforms, weights.centres.data() + at, weights.weights.data() + at, k);
    }
  });
  mesh.rest.resize(static_cast<size_t>(vertices));
  for (int v = 0; v < vertices; ++v)
    mesh.rest[static_cast<size_t>(v)] = frame_mesh.positions.row(v);
  mesh.triangles.resize(static_cast<size_t>(frame_mesh.triangle_count()));
  for (int t = 0; t < frame_mesh.triangle_count(); ++t) {
    mesh.triangles[static_cast<size_t>(t)] = {
        frame_mesh.triangles(t, 0), frame_mesh.triangles(t, 1), frame_mesh.triangles(t, 2)};
  }
  return mesh;
}

// Keys (EdgeKey) of the edges whose ends' relative rotation exceeds zeta, i.e. where
// cos(angle(T_a T_b*) / 2) < split_cosine = cos(zeta / 2); sorted, each once.
std::vector<uint64_t> EdgesToSplit(const RefiningMesh& mesh, double split_cosine) {
  std::vector<uint64_t> split_edges;
  for (const auto& triangle : mesh.triangles) {
    for (int corner = 0; corner < 3; ++corner) {
      const int32_t a = triangle[corner], b = triangle[(corner + 1) % 3];
      const DualQuaternion delta = mesh.transforms[static_cast<size_t>(a)] *
                                   mesh.transforms[static_cast<size_t>(b)].Conjugate();
      if (std::abs(delta.real().w()) < split_cosine * delta.real().norm()) {
        split_edges.push_back(EdgeKey(a, b));
      }
    }
  }
  std::sort(split_edges.begin(), split_edges.end());
  split_edges.erase(std::unique(split_edges.begin(), split_edges.end()), split_edges.end());
  return split_edges;
}

// Appends one midpoint per split edge (in key order), weighted and transformed like any vertex of
// the frame.
void AddMidpoints(const AffinityGraph& graph, int frame, std::span<const DualQuaternion> transforms,
                  const SurfaceOptions& options, const std::vector<uint64_t>& split_edges,
                  RefiningMesh& mesh) {
  const size_t first_new = mesh.rest.size();
  mesh.rest.resize(mesh.rest.size() + split_edges.size());
  mesh.transforms.resize(mesh.rest.size());
  tbb::parallel_for(size_t{0}, split_edges.size(), [&](size_t e) {
    const auto a = static_cast<size_t>(split_edges[e] >> 32);
    const auto b = static_cast<size_t>(split_edges[e] & 0xffffffffu);
    const Eigen::Vector3d midpoint = 0.5 * (mesh.rest[a] + mesh.rest[b]);
    std::vector<int32_t> centres;
    std::vector<double> vertex_weights;
    ComputeVertexWeights(graph, frame, midpoint, options, centres, vertex_weights);
    mesh.rest[first_new + e] = midpoint;
    mesh.transforms[first_new + e] = VertexTransform(
        transforms, centres.data(), vertex_weights.data(), static_cast<int>(centres.size()));
  });
}

// Red-green refinement of one triangle keeping its orientation: 1, 2 or 3 split edges give 2, 3
// or 4 triangles (Fig. 4 of the paper for one edge). mid[c] is the midpoint of edge
// (c, c+1), or -1 when that edge is not split.
void RefineTriangle(const Triangle& triangle, const Triangle& mid, std::vector<Triangle>& refined) {
  int split = 0;
  for (int corner = 0; corner < 3; ++corner) split += mid[corner] >= 0 ? 1 : 0;
  if (split == 0) {
    refined.push_back(triangle);
    return;
  }
  if (split == 3) {
    const auto [a, b, c] = triangle;
    refined.push_back({a, mid[0], mid[2]});
    refined.push_back({mid[0], b, mid[1]});
    refined.push_back({mid[2], mid[1], c});
    refined.push_back({mid[0], mid[1], mid[2]});
    return;
  }
  // Rotate the corners so that edge 0 (a-b) is split and, for two splits, edge 1 (b-c) too.
  int shift = 0;
  for (int r = 0; r < 3; ++r) {
    const bool first = mid[r] >= 0, second = mid[(r + 1) % 3] >= 0;
    if (split == 1 ? first : (first && second)) {
      shift = r;
      break;
    }
  }
  const int32_t a = triangle[shift], b = triangle[(shift + 1) % 3], c = triangle[(shift + 2) % 3];
  const int32_t m_ab = mid[shift], m_bc = mid[(shift + 1) % 3];
  if (split == 1) {
    refined.push_back({a, m_ab, c});
    refined.push_back({m_ab, b, c});
  } else {
    refined.push_back({m_ab, b, m_bc});
    refined.push_back({a, m_ab, m_bc});
    refined.push_back({a, m_bc, c});
  }
}

// Every triangle refined at the split edges, whose midpoints are vertices first_new, first_new+1,
// ... in the order of `split_edges`.
std::vector<Triangle> RefineTriangles(const std::vector<Triangle>& triangles,
                                      const std::vector<uint64_t>& split_edges, int32_t first_new) {
  const auto midpoint_of = [&](int32_t a, int32_t b) -> int32_t {
    const auto it = std::lower_bound(split_edges.begin(), split_edges.end(), EdgeKey(a, b));
    if (it == split_edges.end() || *it != EdgeKey(a, b)) return -1;
    return first_new + static_cast<int32_t>(it - split_edges.begin());
  };
  std::vector<Triangle> refined;
  refined.reserve(triangles.size() * 2);
  for (const auto& triangle : triangles) {
    Triangle mid{};
    for (int corner = 0; corner < 3; ++corner) {
      mid[corner] = midpoint_of(triangle[corner], triangle[(corner + 1) % 3]);
    }
    RefineTriangle(triangle, mid, refined);
  }
  return refined;
}

// The mesh with every vertex moved by its transform.
TvmFrame PosedFrame(const RefiningMesh& mesh) {
  TvmFrame result;
  result.positions.resize(static_cast<Eigen::Index>(mesh.rest.size()), 3);
  tbb::parallel_for(size_t{0}, mesh.rest.size(), [&](size_t v) {
    result.positions.row(static_cast<Eigen::Index>(v)) =
        mesh.transforms[v].Apply(mesh.rest[v]).transpose();
  });
  result.triangles.resize(static_cast<Eigen::Index>(mesh.triangles.size()), 3);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      result.triangles(static_cast<Eigen::Index>(t), corner) = mesh.triangles[t][corner];
    }
  }
  return result;
}

}  // namespace

TvmFrame DeformFrame(const AffinityGraph& graph, int frame, const TvmFrame& frame_mesh,
                     std::span<const DualQuaternion> transforms, const SurfaceOptions& options,
                     const SurfaceWeights* weights, int* vertices_added) {
  SurfaceWeights computed;
  if (weights == nullptr) {
    computed = ComputeSurfaceWeights(graph, frame, frame_mesh.positions, options);
    weights = &computed;
  }
  RefiningMesh mesh = StartRefining(frame_mesh, transforms, *weights);
  const double split_cosine = std::cos(0.5 * options.subdivision_angle);
  for (int round = 0; round < options.subdivision_iterations; ++round) {
    const std::vector<uint64_t> split_edges = EdgesToSplit(mesh, split_cosine);
    if (split_edges.empty()) break;
    const auto first_new = static_cast<int32_t>(mesh.rest.size());
    AddMidpoints(graph, frame, transforms, options, split_edges, mesh);
    mesh.triangles = RefineTriangles(mesh.triangles, split_edges, first_new);
  }
  if (vertices_added != nullptr) {
    *vertices_added = static_cast<int>(mesh.rest.size()) - frame_mesh.vertex_count();
  }
  return PosedFrame(mesh);
}

}  // namespace dmc::tvm

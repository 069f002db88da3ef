// Surface geometry of the B-spline operator: the triangle cubature rule, clipping triangles at the
// voxel planes, Monte Carlo samples, and the 27 quadratic B-splines around a voxel.
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "bspline/bspline_internal.h"

namespace dmc::bspline_detail {
namespace {

// A point is on a voxel face when its local coordinate is within this many grid units of 0 or 1;
// nodes whose restriction vanishes there (u²/2 at u = 0, (1−u)²/2 at u = 1) are not counted as
// touching the piece, so they are not kept with an all-zero row.
constexpr double kFaceTolerance = 1e-9;

// Pieces whose area is below this fraction of their triangle's are rounding slivers of clipping
// through a vertex or along an edge; they carry no integral but would keep spurious nodes.
constexpr double kSliverFraction = 1e-12;

struct ClipVertex {
  Eigen::Vector3d grid;
  Eigen::Vector3d barycentric;
};

// A convex polygon; clipping a triangle by axis planes never exceeds 9 vertices.
struct ClipPolygon {
  std::array<ClipVertex, 12> vertices;
  int count = 0;
  void Push(const ClipVertex& v) { vertices[count++] = v; }
};

// Sutherland–Hodgman against the plane grid[axis] = c, both halves at once. Vertices on the
// plane go to both halves; crossing points get the plane coordinate exactly.
void SplitPolygon(const ClipPolygon& in, int axis, double c, ClipPolygon& below,
                  ClipPolygon& above) {
  below.count = 0;
  above.count = 0;
  for (int k = 0; k < in.count; ++k) {
    const ClipVertex& a = in.vertices[k];
    const ClipVertex& b = in.vertices[(k + 1) % in.count];
    const double da = a.grid[axis] - c;
    const double db = b.grid[axis] - c;
    if (da <= 0.0) below.Push(a);
    if (da >= 0.0) above.Push(a);
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
      const double t = da / (da - db);
      ClipVertex cut{a.grid + t * (b.grid - a.grid),
                     a.barycentric + t * (b.barycentric - a.barycentric)};
      cut.grid[axis] = c;
      below.Push(cut);
      above.Push(cut);
    }
  }
}

// Splits every polygon of `polygons` at the integer planes of `axis` crossing it.
std::vector<ClipPolygon> SplitAlongAxis(const std::vector<ClipPolygon>& polygons, int axis) {
  std::vector<ClipPolygon> out;
  for (const ClipPolygon& polygon : polygons) {
    double low = polygon.vertices[0].grid[axis], high = low;
    for (int k = 1; k < polygon.count; ++k) {
      low = std::min(low, polygon.vertices[k].grid[axis]);
      high = std::max(high, polygon.vertices[k].grid[axis]);
    }
    ClipPolygon rest = polygon;
    ClipPolygon below, above;
    for (double plane = std::floor(low) + 1.0; plane < high; plane += 1.0) {
      SplitPolygon(rest, axis, plane, below, above);
      if (below.count >= 3) out.push_back(below);
      rest = above;
      if (rest.count < 3) break;
    }
    if (rest.count >= 3) out.push_back(rest);
  }
  return out;
}

// Which of the 27 nodes around `voxel` are non-zero at local point `grid`.
uint32_t NodeMaskAt(const Eigen::Vector3i& voxel, const Eigen::Vector3d& grid) {
  std::array<std::array<bool, 3>, 3> allowed;
  for (int axis = 0; axis < 3; ++axis) {
    const double u = grid[axis] - voxel[axis];
    allowed[axis] = {u<1.0 - kFaceTolerance, true, u> kFaceTolerance};
  }
  uint32_t mask = 0;
  for (int ox = -1; ox <= 1; ++ox) {
    for (int oy = -1; oy <= 1; ++oy) {
      for (int oz = -1; oz <= 1; ++oz) {
        if (allowed[0][ox + 1] && allowed[1][oy + 1] && allowed[2][oz + 1]) {
          mask |= uint32_t{1} << LocalIndex(ox, oy, oz);
        }
      }
    }
  }
  return mask;
}

Eigen::Vector3i VoxelOf(const Eigen::Vector3d& grid, int resolution) {
  Eigen::Vector3i voxel;
  for (int axis = 0; axis < 3; ++axis) {
    voxel[axis] = std::clamp(static_cast<int>(std::floor(grid[axis])), 0, resolution - 1);
  }
  return voxel;
}

void SortByVoxel(std::vector<SurfacePiece>& pieces) {
  std::stable_sort(pieces.begin(), pieces.end(),
                   [](const SurfacePiece& a, const SurfacePiece& b) { return a.voxel < b.voxel; });
}

}  // namespace

TriangleRule CollapsedGaussRule(int degree) {
  const int n = std::max(1, (degree + 3) / 2);  // ⌈(degree + 2)/2⌉
  // Golub–Welsch: Gauss–Legendre nodes are the eigenvalues of the Jacobi matrix with
  // off-diagonals k / sqrt(4k² − 1); weights are 2·(first eigenvector component)².
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) {
    const double beta = k / std::sqrt(4.0 * k * k - 1.0);
    jacobi(k, k - 1) = beta;
    jacobi(k - 1, k) = beta;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jacobi);
  std::vector<double> nodes(n), weights(n);
  for (int k = 0; k < n; ++k) {
    nodes[k] = 0.5 * (eigen.eigenvalues()[k] + 1.0);  // on [0, 1]
    const double first = eigen.eigenvectors()(0, k);
    weights[k] = first * first;  // 2·first² on [−1, 1], halved on [0, 1]
  }
  TriangleRule rule;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      // (u, v) ∈ [0,1]² ↦ s = u, t = (1 − u)·v; Jacobian (1 − u); the reference triangle has
      // area ½, so weights are doubled to sum to one.
      const double s = nodes[i];
      const double t = (1.0 - nodes[i]) * nodes[j];
      rule.barycentric.emplace_back(1.0 - s - t, s, t);
      rule.weights.push_back(2.0 * weights[i] * weights[j] * (1.0 - nodes[i]));
    }
  }
  return rule;
}

SurfaceMesh DescribeSurface(const Triangles& triangles, const FramePositionsD& positions) {
  SurfaceMesh mesh;
  mesh.triangles = &triangles;
  mesh.positions = &positions;
  const Eigen::Index count = triangles.rows();
  mesh.normals.resize(count);
  mesh.areas.resize(count);
  for (Eigen::Index t = 0; t < count; ++t) {
    const Eigen::Vector3d a = positions.row(triangles(t, 0)).transpose();
    const Eigen::Vector3d b = positions.row(triangles(t, 1)).transpose();
    const Eigen::Vector3d c = positions.row(triangles(t, 2)).transpose();
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double norm = cross.norm();
    mesh.areas[t] = 0.5 * norm;
    mesh.normals[t] = norm > 0.0 ? Eigen::Vector3d(cross / norm) : Eigen::Vector3d::Zero();
    mesh.total_area += mesh.areas[t];
  }
  return mesh;
}

Eigen::Vector3d ToGrid(const BsplineFrame& frame, int depth, const Eigen::Vector3d& world) {
  return (world - frame.origin) * (std::ldexp(1.0, depth) / frame.cube_size);
}

std::vector<SurfacePiece> ClipSurface(const SurfaceMesh& mesh, const BsplineFrame& frame,
                                      int depth) {
  const Triangles& triangles = *mesh.triangles;
  const FramePositionsD& positions = *mesh.positions;
  const int resolution = 1 << depth;
  const int triangle_count = static_cast<int>(triangles.rows());
  const double world_per_grid_area = std::pow(frame.cube_size / resolution, 2);

  // Triangles are clipped in parallel chunks whose outputs are concatenated in order.
  constexpr int kChunk = 1024;
  const int chunks = (triangle_count + kChunk - 1) / kChunk;
  std::vector<std::vector<SurfacePiece>> chunk_pieces(chunks);
  tbb::parallel_for(0, chunks, [&](int chunk) {
    std::vector<SurfacePiece>& out = chunk_pieces[chunk];
    const int end = std::min(triangle_count, (chunk + 1) * kChunk);
    for (int t = chunk * kChunk; t < end; ++t) {
      if (mesh.areas[t] <= 0.0) continue;
      ClipPolygon triangle;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();
        barycentric[k] = 1.0;
        triangle.Push(
            {ToGrid(frame, depth, positions.row(triangles(t, k)).transpose()), barycentric});
      }
      std::vector<ClipPolygon> polygons{triangle};
      for (int axis = 0; axis < 3; ++axis) polygons = SplitAlongAxis(polygons, axis);
      const double grid_area = mesh.areas[t] / world_per_grid_area;
      for (const ClipPolygon& polygon : polygons) {
        const ClipVertex& apex = polygon.vertices[0];
        for (int k = 1; k + 1 < polygon.count; ++k) {  // fan: convex polygon
          const ClipVertex& b = polygon.vertices[k];
          const ClipVertex& c = polygon.vertices[k + 1];
          const double area = 0.5 * (b.grid - apex.grid).cross(c.grid - apex.grid).norm();
          if (area <= kSliverFraction * grid_area) continue;
          SurfacePiece piece;
          piece.triangle = t;
          piece.grid = {apex.grid, b.grid, c.grid};
          piece.barycentric = {apex.barycentric, b.barycentric, c.barycentric};
          piece.weight = area * world_per_grid_area;
          const Eigen::Vector3d centroid = (apex.grid + b.grid + c.grid) / 3.0;
          const Eigen::Vector3i voxel = VoxelOf(centroid, resolution);
          piece.voxel = PackKey(voxel.x(), voxel.y(), voxel.z());
          piece.node_mask = NodeMaskAt(voxel, centroid);
          out.push_back(piece);
        }
      }
    }
  });
  std::vector<SurfacePiece> pieces;
  size_t total = 0;
  for (const auto& chunk : chunk_pieces) total += chunk.size();
  pieces.reserve(total);
  for (auto& chunk : chunk_pieces) pieces.insert(pieces.end(), chunk.begin(), chunk.end());
  SortByVoxel(pieces);
  return pieces;
}

std::vector<SurfaceSample> SampleSurface(const SurfaceMesh& mesh, int64_t count, uint64_t seed) {
  std::vector<double> cumulative(mesh.areas.size());
  std::partial_sum(mesh.areas.begin(), mesh.areas.end(), cumulative.begin());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<SurfaceSample> samples(static_cast<size_t>(count));
  for (SurfaceSample& sample : samples) {
    const double target = unit(rng) * mesh.total_area;
    const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), target);
    sample.triangle = static_cast<int32_t>(
        std::min<std::ptrdiff_t>(it - cumulative.begin(), std::ssize(cumulative) - 1));
    // Uniform in the triangle: the square-root warp of two uniforms.
    const double r1 = std::sqrt(unit(rng)), r2 = unit(rng);
    sample.barycentric = {1.0 - r1, r1 * (1.0 - r2), r1 * r2};
  }
  return samples;
}

std::vector<SurfacePiece> SamplePieces(const SurfaceMesh& mesh,
                                       const std::vector<SurfaceSample>& samples,
                                       const BsplineFrame& frame, int depth) {
  const Triangles& triangles = *mesh.triangles;
  const FramePositionsD& positions = *mesh.positions;
  const int resolution = 1 << depth;
  const double weight = mesh.total_area / static_cast<double>(std::max<size_t>(1, samples.size()));
  std::vector<SurfacePiece> pieces(samples.size());
  tbb::parallel_for(size_t{0}, samples.size(), [&](size_t s) {
    const SurfaceSample& sample = samples[s];
    Eigen::Vector3d world = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      world += sample.barycentric[k] * positions.row(triangles(sample.triangle, k)).transpose();
    }
    SurfacePiece& piece = pieces[s];
    piece.triangle = sample.triangle;
    piece.corner_count = 1;
    piece.grid[0] = ToGrid(frame, depth, world);
    piece.barycentric[0] = sample.barycentric;
    piece.weight = weight;
    const Eigen::Vector3i voxel = VoxelOf(piece.grid[0], resolution);
    piece.voxel = PackKey(voxel.x(), voxel.y(), voxel.z());
    piece.node_mask = NodeMaskAt(voxel, piece.grid[0]);
  });
  SortByVoxel(pieces);
  return pieces;
}

void PiecePoints(const SurfacePiece& piece, const TriangleRule& rule,
                 std::vector<PiecePoint>& out) {
  if (piece.corner_count == 1) {
    out.push_back({piece.grid[0], piece.barycentric[0], piece.weight});
    return;
  }
  for (size_t q = 0; q < rule.weights.size(); ++q) {
    const Eigen::Vector3d& l = rule.barycentric[q];
    out.push_back(
        {l[0] * piece.grid[0] + l[1] * piece.grid[1] + l[2] * piece.grid[2],
         l[0] * piece.barycentric[0] + l[1] * piece.barycentric[1] + l[2] * piece.barycentric[2],
         rule.weights[q] * piece.weight});
  }
}

void EvaluateVoxelNodes(const Eigen::Vector3i& voxel, const Eigen::Vector3d& grid, double value[27],
                        Eigen::Vector3d gradient[27]) {
  double v[3][3], d[3][3];
  for (int axis = 0; axis < 3; ++axis) QuadraticPieces(grid[axis] - voxel[axis], v[axis], d[axis]);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) {
        const int local = i * 9 + j * 3 + k;
        value[local] = v[0][i] * v[1][j] * v[2][k];
        gradient[local] = {d[0][i] * v[1][j] * v[2][k], v[0][i] * d[1][j] * v[2][k],
                           v[0][i] * v[1][j] * d[2][k]};
      }
    }
  }
}

}  // namespace dmc::bspline_detail

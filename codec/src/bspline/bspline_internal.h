// Internals of dmc_bspline shared by its translation units: node keys, the 1D quadratic B-spline
// pieces, the triangle cubature, surface pieces per voxel and the per-voxel local matrices.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "dmc/bspline.h"

namespace dmc::bspline_detail {

// Node and voxel keys: x, y, z (shifted by +2 so that −1 … 2^10 are non-negative) in 21 bits each,
// x most significant, so sorting keys sorts by x, then y, then z.
constexpr int kKeyShift = 2;
inline uint64_t PackKey(int x, int y, int z) {
  return (static_cast<uint64_t>(x + kKeyShift) << 42) |
         (static_cast<uint64_t>(y + kKeyShift) << 21) | static_cast<uint64_t>(z + kKeyShift);
}
inline Eigen::Vector3i UnpackKey(uint64_t key) {
  const uint64_t mask = (uint64_t{1} << 21) - 1;
  return {static_cast<int>((key >> 42) & mask) - kKeyShift,
          static_cast<int>((key >> 21) & mask) - kKeyShift,
          static_cast<int>(key & mask) - kKeyShift};
}

// The three quadratic B-spline pieces that are non-zero inside a voxel, at local coordinate
// u ∈ [0, 1]: index 0 belongs to the node one voxel below (offset −1), 1 to the voxel's own node,
// 2 to the node above. They sum to one and their derivatives (per grid unit) sum to zero.
inline void QuadraticPieces(double u, double value[3], double derivative[3]) {
  value[0] = 0.5 * (1.0 - u) * (1.0 - u);
  value[1] = 0.75 - (u - 0.5) * (u - 0.5);
  value[2] = 0.5 * u * u;
  derivative[0] = u - 1.0;
  derivative[1] = 1.0 - 2.0 * u;
  derivative[2] = u;
}

// Local index of the node at offset (ox, oy, oz) ∈ {−1, 0, 1}³ from a voxel, in key order.
constexpr int LocalIndex(int ox, int oy, int oz) { return (ox + 1) * 9 + (oy + 1) * 3 + (oz + 1); }

// Cubature on the reference triangle, exact for polynomials of `degree`: barycentric points and
// weights summing to one (multiply by the area).
struct TriangleRule {
  std::vector<Eigen::Vector3d> barycentric;
  std::vector<double> weights;
};
// Collapsed (Duffy) Gauss–Legendre product rule with n = ⌈(degree + 2)/2⌉ points per direction:
// the collapse adds one degree in the collapsed direction, and n Gauss points integrate degree
// 2n − 1 exactly. Nodes from the Golub–Welsch eigenproblem.
TriangleRule CollapsedGaussRule(int degree);

// A surface piece lying in one voxel: a sub-triangle of mesh triangle `triangle` (cubature), or
// a single Monte Carlo sample (corner_count = 1, `weight` = its share of the area).
struct SurfacePiece {
  uint64_t voxel = 0;  // PackKey of the voxel
  int32_t triangle = 0;
  int32_t corner_count = 3;
  std::array<Eigen::Vector3d, 3> grid;         // corners in grid units of the level
  std::array<Eigen::Vector3d, 3> barycentric;  // corners in the mesh triangle's barycentrics
  double weight = 0.0;                         // world area of the piece (or sample weight)
  uint32_t node_mask = 0;  // bit LocalIndex(o): the node at offset o is non-zero on the piece
};

// The mesh in world units plus per-triangle unit normals and areas.
struct SurfaceMesh {
  const Triangles* triangles = nullptr;
  const FramePositionsD* positions = nullptr;
  std::vector<Eigen::Vector3d> normals;  // unit, (b − a) × (c − a) direction; zero if degenerate
  std::vector<double> areas;
  double total_area = 0.0;
};
SurfaceMesh DescribeSurface(const Triangles& triangles, const FramePositionsD& positions);

// Grid units of depth `depth`: (p − origin) / cube_size · 2^depth.
Eigen::Vector3d ToGrid(const BsplineFrame& frame, int depth, const Eigen::Vector3d& world);

// All pieces at `depth`, sorted by voxel key (ties keep triangle order: deterministic).
std::vector<SurfacePiece> ClipSurface(const SurfaceMesh& mesh, const BsplineFrame& frame,
                                      int depth);

// A Monte Carlo sample set: area-uniform points (triangle, barycentric), weight area / count.
struct SurfaceSample {
  int32_t triangle = 0;
  Eigen::Vector3d barycentric;
};
std::vector<SurfaceSample> SampleSurface(const SurfaceMesh& mesh, int64_t count, uint64_t seed);
std::vector<SurfacePiece> SamplePieces(const SurfaceMesh& mesh,
                                       const std::vector<SurfaceSample>& samples,
                                       const BsplineFrame& frame, int depth);

// Integration points of one piece: grid position, world weight, barycentric in its triangle.
struct PiecePoint {
  Eigen::Vector3d grid;
  Eigen::Vector3d barycentric;
  double weight = 0.0;
};
void PiecePoints(const SurfacePiece& piece, const TriangleRule& rule, std::vector<PiecePoint>& out);

// Values and grid-unit gradients of the 27 nodes around `voxel` at a grid point.
void EvaluateVoxelNodes(const Eigen::Vector3i& voxel, const Eigen::Vector3d& grid, double value[27],
                        Eigen::Vector3d gradient[27]);

// C (n×V), C_iv = ∫ b_i φ_v with φ_v the hat function of vertex v, integrated exactly on the
// finest level's pieces. Row sums are ∫ b_i, column sums ∫ φ_v.
SparseMatrixD HatFunctionCoupling(const BsplineOperator& op);

}  // namespace dmc::bspline_detail

// The pruned octree, the stiffness and mass matrices per level, the prolongations, evaluation at
// points, and load vectors of per-vertex fields.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "bspline/bspline_internal.h"

namespace dmc {
namespace {

using namespace bspline_detail;

constexpr int kMaxDepth = 10;
constexpr int kNoNode = -1;

// Sorted node keys of one level with lookup.
struct NodeIndex {
  std::vector<uint64_t> keys;
  int Find(uint64_t key) const {
    const auto it = std::lower_bound(keys.begin(), keys.end(), key);
    return it != keys.end() && *it == key ? static_cast<int>(it - keys.begin()) : kNoNode;
  }
};

// The pieces of one voxel and its 27 surrounding nodes (kNoNode when not kept).
struct VoxelBlock {
  Eigen::Vector3i voxel;
  size_t first_piece = 0, end_piece = 0;
  uint32_t node_mask = 0;
  std::array<int, 27> node{};
};

std::vector<VoxelBlock> GroupByVoxel(const std::vector<SurfacePiece>& pieces) {
  std::vector<VoxelBlock> blocks;
  for (size_t p = 0; p < pieces.size();) {
    VoxelBlock block;
    block.voxel = UnpackKey(pieces[p].voxel);
    block.first_piece = p;
    while (p < pieces.size() && pieces[p].voxel == pieces[block.first_piece].voxel) {
      block.node_mask |= pieces[p].node_mask;
      ++p;
    }
    block.end_piece = p;
    blocks.push_back(block);
  }
  return blocks;
}

Eigen::Vector3i LocalOffset(int local) {
  return {local / 9 - 1, (local / 3) % 3 - 1, local % 3 - 1};
}

// Kept nodes: every node non-zero on some piece. Fills each block's node table.
NodeIndex KeepNodes(std::vector<VoxelBlock>& blocks) {
  NodeIndex index;
  for (const VoxelBlock& block : blocks) {
    for (int local = 0; local < 27; ++local) {
      if (!(block.node_mask >> local & 1u)) continue;
      const Eigen::Vector3i node = block.voxel + LocalOffset(local);
      index.keys.push_back(PackKey(node.x(), node.y(), node.z()));
    }
  }
  std::sort(index.keys.begin(), index.keys.end());
  index.keys.erase(std::unique(index.keys.begin(), index.keys.end()), index.keys.end());
  tbb::parallel_for(size_t{0}, blocks.size(), [&](size_t b) {
    VoxelBlock& block = blocks[b];
    for (int local = 0; local < 27; ++local) {
      block.node[local] = kNoNode;
      if (!(block.node_mask >> local & 1u)) continue;
      const Eigen::Vector3i node = block.voxel + LocalOffset(local);
      block.node[local] = index.Find(PackKey(node.x(), node.y(), node.z()));
    }
  });
  return index;
}

// Offset code of node q relative to node p (both local to one voxel): (Δ + 2) in base 5, which
// orders a row's columns exactly like their keys.
int CouplingCode(int p, int q) {
  const Eigen::Vector3i d = LocalOffset(q) - LocalOffset(p);
  return (d.x() + 2) * 25 + (d.y() + 2) * 5 + (d.z() + 2);
}

// A row's 125 possible couplings as a bit set; the slot of a column is the rank of its bit.
struct RowMask {
  uint64_t bits[2] = {0, 0};
  void Set(int code) { bits[code >> 6] |= uint64_t{1} << (code & 63); }
  int Count() const { return std::popcount(bits[0]) + std::popcount(bits[1]); }
  int Rank(int code) const {
    const uint64_t below = code & 63 ? (uint64_t{1} << (code & 63)) - 1 : 0;
    return code < 64 ? std::popcount(bits[0] & below)
                     : std::popcount(bits[0]) + std::popcount(bits[1] & below);
  }
};

// Local 27×27 stiffness K = Σ w ∇_M b ∇_M bᵀ and mass D = Σ w b bᵀ of one voxel (lower triangles).
struct LocalMatrices {
  Eigen::Matrix<double, 27, 27> stiffness;
  Eigen::Matrix<double, 27, 27> mass;
};

void IntegrateVoxel(const VoxelBlock& block, const std::vector<SurfacePiece>& pieces,
                    const SurfaceMesh& mesh, const TriangleRule& rule, double grid_to_world,
                    std::vector<PiecePoint>& points, LocalMatrices& out) {
  points.clear();
  std::vector<int32_t> point_triangle;
  for (size_t p = block.first_piece; p < block.end_piece; ++p) {
    const size_t before = points.size();
    PiecePoints(pieces[p], rule, points);
    point_triangle.insert(point_triangle.end(), points.size() - before, pieces[p].triangle);
  }
  const Eigen::Index count = static_cast<Eigen::Index>(points.size());
  Eigen::Matrix<double, 27, Eigen::Dynamic> values(27, count);
  Eigen::Matrix<double, 27, Eigen::Dynamic> gradients(27, 3 * count);
  double value[27];
  Eigen::Vector3d gradient[27];
  for (Eigen::Index q = 0; q < count; ++q) {
    EvaluateVoxelNodes(block.voxel, points[q].grid, value, gradient);
    const double root = std::sqrt(points[q].weight);
    const Eigen::Vector3d& normal = mesh.normals[point_triangle[q]];
    for (int local = 0; local < 27; ++local) {
      values(local, q) = root * value[local];
      // World gradient (grid gradient / voxel width) projected on the tangent plane.
      Eigen::Vector3d g = gradient[local] * grid_to_world;
      g -= g.dot(normal) * normal;
      gradients.block<1, 3>(local, 3 * q) = root * g.transpose();
    }
  }
  out.mass.setZero();
  out.stiffness.setZero();
  out.mass.selfadjointView<Eigen::Lower>().rankUpdate(values);
  out.stiffness.selfadjointView<Eigen::Lower>().rankUpdate(gradients);
}

// Integrates one level from its pieces: node set, L = −K and D in one shared CSR pattern.
BsplineLevel AssembleLevel(const SurfaceMesh& mesh, const BsplineFrame& frame, int depth,
                           const std::vector<SurfacePiece>& pieces, const TriangleRule& rule,
                           NodeIndex& index) {
  BsplineLevel level;
  level.depth = depth;
  level.pieces = static_cast<int64_t>(pieces.size());
  std::vector<VoxelBlock> blocks = GroupByVoxel(pieces);
  index = KeepNodes(blocks);
  const int n = static_cast<int>(index.keys.size());
  level.nodes.reserve(n);
  for (uint64_t key : index.keys) level.nodes.push_back(UnpackKey(key));

  // Sparsity: node p couples to q when both are non-zero on a common voxel's pieces.
  std::vector<RowMask> rows(n);
  for (const VoxelBlock& block : blocks) {
    for (int p = 0; p < 27; ++p) {
      if (block.node[p] == kNoNode) continue;
      for (int q = 0; q < 27; ++q) {
        if (block.node[q] != kNoNode) rows[block.node[p]].Set(CouplingCode(p, q));
      }
    }
  }
  std::vector<int> outer(n + 1, 0);
  for (int i = 0; i < n; ++i) outer[i + 1] = outer[i] + rows[i].Count();
  const int nonzeros = outer[n];
  std::vector<int> inner(nonzeros, 0);
  std::vector<double> stiffness(nonzeros, 0.0), mass(nonzeros, 0.0);

  // Local matrices in parallel batches, scattered serially in voxel order (deterministic sums).
  const double grid_to_world = std::ldexp(1.0, depth) / frame.cube_size;
  constexpr size_t kBatch = 1024;
  std::vector<LocalMatrices> locals(std::min(kBatch, blocks.size()));
  for (size_t start = 0; start < blocks.size(); start += kBatch) {
    const size_t end = std::min(blocks.size(), start + kBatch);
    tbb::parallel_for(start, end, [&](size_t b) {
      thread_local std::vector<PiecePoint> points;
      IntegrateVoxel(blocks[b], pieces, mesh, rule, grid_to_world, points, locals[b - start]);
    });
    for (size_t b = start; b < end; ++b) {
      const VoxelBlock& block = blocks[b];
      const LocalMatrices& local = locals[b - start];
      for (int p = 0; p < 27; ++p) {
        const int row = block.node[p];
        if (row == kNoNode) continue;
        for (int q = 0; q < 27; ++q) {
          const int column = block.node[q];
          if (column == kNoNode) continue;
          const int slot = outer[row] + rows[row].Rank(CouplingCode(p, q));
          inner[slot] = column;
          // Lower triangles only: (p, q) and (q, p) read the same number, so L and D are
          // exactly symmetric.
          stiffness[slot] += p >= q ? local.stiffness(p, q) : local.stiffness(q, p);
          mass[slot] += p >= q ? local.mass(p, q) : local.mass(q, p);
        }
      }
    }
  }
  for (double& value : stiffness) value = -value;
  // Symmetric, so the row-wise arrays are also the column-major ones.
  level.laplacian =
      Eigen::Map<const SparseMatrixD>(n, n, nonzeros, outer.data(), inner.data(), stiffness.data());
  level.mass =
      Eigen::Map<const SparseMatrixD>(n, n, nonzeros, outer.data(), inner.data(), mass.data());
  return level;
}

// P (n_fine × n_coarse): coarse node c is Σ w fine nodes 2c + δ, δ ∈ {−1, 0, 1, 2}, with the
// tensor product of ¼(1 3 3 1). Fine nodes that were pruned vanish on the surface, so omitting
// them keeps the restricted identity exact.
SparseMatrixD Prolongation(const BsplineLevel& coarse, const NodeIndex& fine, int fine_count) {
  constexpr double kStencil[4] = {0.25, 0.75, 0.75, 0.25};
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(coarse.nodes.size() * 27);
  for (int c = 0; c < coarse.dimension(); ++c) {
    const Eigen::Vector3i& node = coarse.nodes[c];
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        for (int k = 0; k < 4; ++k) {
          const int f =
              fine.Find(PackKey(2 * node.x() + i - 1, 2 * node.y() + j - 1, 2 * node.z() + k - 1));
          if (f != kNoNode) triplets.emplace_back(f, c, kStencil[i] * kStencil[j] * kStencil[k]);
        }
      }
    }
  }
  SparseMatrixD p(fine_count, coarse.dimension());
  p.setFromTriplets(triplets.begin(), triplets.end());
  return p;
}

Status ValidateInput(const Triangles& triangles, const FramePositionsD& positions,
                     const BsplineOptions& options) {
  if (options.depth < 1 || options.depth > kMaxDepth) {
    return InvalidArgumentError("B-spline depth must be in [1, " + std::to_string(kMaxDepth) +
                                "], got " + std::to_string(options.depth));
  }
  if (options.cubature_degree < 1 || options.cubature_degree > 40) {
    return InvalidArgumentError("B-spline cubature degree must be in [1, 40], got " +
                                std::to_string(options.cubature_degree));
  }
  if (options.monte_carlo_samples < 0) {
    return InvalidArgumentError("Monte Carlo sample count must be >= 0");
  }
  if (!positions.allFinite()) return InvalidArgumentError("B-spline operator: non-finite position");
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (triangles(t, k) < 0 || triangles(t, k) >= positions.rows()) {
        return InvalidArgumentError("B-spline operator: triangle " + std::to_string(t) +
                                    " has a vertex index outside [0, " +
                                    std::to_string(positions.rows()) + ")");
      }
    }
  }
  return Status::Ok();
}

// The smallest cube around the referenced vertices, centred on their bounding box.
StatusOr<BsplineFrame> FrameOf(const Triangles& triangles, const FramePositionsD& positions) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = positions.row(triangles(t, k)).transpose();
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
  }
  BsplineFrame frame;
  frame.cube_size = triangles.rows() > 0 ? (high - low).maxCoeff() : 0.0;
  if (!(frame.cube_size > 0.0)) {
    return InvalidArgumentError("B-spline operator: the mesh has no extent (no triangles)");
  }
  frame.origin = 0.5 * (low + high) - Eigen::Vector3d::Constant(0.5 * frame.cube_size);
  return frame;
}

NodeIndex IndexOf(const BsplineLevel& level) {
  NodeIndex index;
  index.keys.reserve(level.nodes.size());
  for (const Eigen::Vector3i& node : level.nodes) {
    index.keys.push_back(PackKey(node.x(), node.y(), node.z()));
  }
  return index;
}

}  // namespace

StatusOr<BsplineOperator> BuildBsplineOperator(const Triangles& triangles,
                                               const FramePositionsD& positions,
                                               const BsplineOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateInput(triangles, positions, options));
  BsplineOperator op;
  DMC_ASSIGN_OR_RETURN(op.frame, FrameOf(triangles, positions));
  op.triangles = triangles;
  op.positions = positions;
  const SurfaceMesh mesh = DescribeSurface(op.triangles, op.positions);
  if (!(mesh.total_area > 0.0)) {
    return InvalidArgumentError("B-spline operator: the mesh has zero area");
  }
  op.area = mesh.total_area;

  const TriangleRule rule = CollapsedGaussRule(options.cubature_degree);
  std::vector<SurfaceSample> samples;
  if (options.integration == BsplineIntegration::kMonteCarlo) {
    const double voxel = op.frame.cube_size / std::ldexp(1.0, options.depth);
    const int64_t count =
        options.monte_carlo_samples > 0
            ? options.monte_carlo_samples
            : std::max<int64_t>(1000,
                                static_cast<int64_t>(64.0 * mesh.total_area / (voxel * voxel)));
    samples = SampleSurface(mesh, count, options.seed);
  }

  const int coarsest = std::clamp(options.coarsest_depth, 1, options.depth);
  for (int depth = coarsest; depth <= options.depth; ++depth) {
    const std::vector<SurfacePiece> pieces = options.integration == BsplineIntegration::kMonteCarlo
                                                 ? SamplePieces(mesh, samples, op.frame, depth)
                                                 : ClipSurface(mesh, op.frame, depth);
    NodeIndex index;
    BsplineLevel level = AssembleLevel(mesh, op.frame, depth, pieces, rule, index);
    if (!op.levels.empty()) {
      op.levels.back().prolongation = Prolongation(op.levels.back(), index, level.dimension());
    }
    op.levels.push_back(std::move(level));
  }

  // Evaluation at the vertices that triangles reference (others keep a zero row).
  std::vector<char> referenced(positions.rows(), 0);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) referenced[triangles(t, k)] = 1;
  }
  op.evaluation = BsplineEvaluationMatrix(op, positions);
  if (std::find(referenced.begin(), referenced.end(), 0) != referenced.end()) {
    Eigen::VectorXd keep(positions.rows());
    for (Eigen::Index v = 0; v < positions.rows(); ++v) keep[v] = referenced[v] ? 1.0 : 0.0;
    op.evaluation = keep.asDiagonal() * op.evaluation;
    op.evaluation.prune(0.0);
  }
  return op;
}

SparseMatrixD BsplineEvaluationMatrix(const BsplineOperator& op, const FramePositionsD& points) {
  const BsplineLevel& level = op.finest();
  const NodeIndex index = IndexOf(level);
  const int resolution = 1 << level.depth;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(points.rows()) * 27);
  double value[27];
  Eigen::Vector3d gradient[27];
  for (Eigen::Index v = 0; v < points.rows(); ++v) {
    const Eigen::Vector3d grid = ToGrid(op.frame, level.depth, points.row(v).transpose());
    Eigen::Vector3i voxel;
    for (int axis = 0; axis < 3; ++axis) {
      voxel[axis] = std::clamp(static_cast<int>(std::floor(grid[axis])), 0, resolution - 1);
    }
    EvaluateVoxelNodes(voxel, grid, value, gradient);
    for (int local = 0; local < 27; ++local) {
      if (value[local] == 0.0) continue;
      const Eigen::Vector3i node = voxel + LocalOffset(local);
      const int column = index.Find(PackKey(node.x(), node.y(), node.z()));
      if (column != kNoNode) triplets.emplace_back(static_cast<int>(v), column, value[local]);
    }
  }
  SparseMatrixD evaluation(points.rows(), level.dimension());
  evaluation.setFromTriplets(triplets.begin(), triplets.end());
  return evaluation;
}

namespace {

// Σ over the finest pieces of `accumulate(node, value, world gradient, point)`.
template <typename Accumulate>
void ForEachFinestPoint(const BsplineOperator& op, const SurfaceMesh& mesh,
                        Accumulate&& accumulate) {
  const BsplineLevel& level = op.finest();
  const NodeIndex index = IndexOf(level);
  const std::vector<SurfacePiece> pieces = ClipSurface(mesh, op.frame, level.depth);
  const TriangleRule rule = CollapsedGaussRule(12);
  const double grid_to_world = std::ldexp(1.0, level.depth) / op.frame.cube_size;
  std::vector<PiecePoint> points;
  double value[27];
  Eigen::Vector3d gradient[27];
  std::array<int, 27> node{};
  for (size_t p = 0; p < pieces.size(); ++p) {
    const SurfacePiece& piece = pieces[p];
    const Eigen::Vector3i voxel = UnpackKey(piece.voxel);
    if (p == 0 || pieces[p - 1].voxel != piece.voxel) {
      for (int local = 0; local < 27; ++local) {
        const Eigen::Vector3i n = voxel + LocalOffset(local);
        node[local] = index.Find(PackKey(n.x(), n.y(), n.z()));
      }
    }
    points.clear();
    PiecePoints(piece, rule, points);
    for (const PiecePoint& point : points) {
      EvaluateVoxelNodes(voxel, point.grid, value, gradient);
      for (int local = 0; local < 27; ++local) {
        if (node[local] == kNoNode) continue;
        accumulate(node[local], piece.triangle, value[local], gradient[local] * grid_to_world,
                   point);
      }
    }
  }
}

}  // namespace

StatusOr<Eigen::MatrixXd> IntegrateValueLoad(const BsplineOperator& op,
                                             const Eigen::MatrixXd& vertex_values) {
  if (vertex_values.rows() != op.positions.rows()) {
    return MismatchError("value field has " + std::to_string(vertex_values.rows()) +
                         " rows, the mesh " + std::to_string(op.positions.rows()) + " vertices");
  }
  const SurfaceMesh mesh = DescribeSurface(op.triangles, op.positions);
  Eigen::MatrixXd load = Eigen::MatrixXd::Zero(op.dimension(), vertex_values.cols());
  ForEachFinestPoint(
      op, mesh,
      [&](int node, int triangle, double value, const Eigen::Vector3d&, const PiecePoint& point) {
        Eigen::RowVectorXd f = Eigen::RowVectorXd::Zero(vertex_values.cols());
        for (int k = 0; k < 3; ++k) {
          f += point.barycentric[k] * vertex_values.row(op.triangles(triangle, k));
        }
        load.row(node) += point.weight * value * f;
      });
  return load;
}

StatusOr<Eigen::MatrixXd> IntegrateGradientLoad(const BsplineOperator& op,
                                                const Eigen::MatrixXd& vertex_values,
                                                double gradient_scale) {
  if (vertex_values.rows() != op.positions.rows()) {
    return MismatchError("value field has " + std::to_string(vertex_values.rows()) +
                         " rows, the mesh " + std::to_string(op.positions.rows()) + " vertices");
  }
  const SurfaceMesh mesh = DescribeSurface(op.triangles, op.positions);
  // Per-triangle surface gradient of each channel: ∇f = Σ_k f_k (n × e_k) / (2A), e_k the edge
  // opposite corner k, counter-clockwise.
  const Eigen::Index channels = vertex_values.cols();
  std::vector<Eigen::Matrix3Xd> gradients(op.triangles.rows(), Eigen::Matrix3Xd::Zero(3, channels));
  for (Eigen::Index t = 0; t < op.triangles.rows(); ++t) {
    if (mesh.areas[t] <= 0.0) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d from = op.positions.row(op.triangles(t, (k + 1) % 3)).transpose();
      const Eigen::Vector3d to = op.positions.row(op.triangles(t, (k + 2) % 3)).transpose();
      const Eigen::Vector3d direction = mesh.normals[t].cross(to - from) / (2.0 * mesh.areas[t]);
      gradients[t] += direction * vertex_values.row(op.triangles(t, k));
    }
    gradients[t] *= gradient_scale;
  }
  Eigen::MatrixXd load = Eigen::MatrixXd::Zero(op.dimension(), channels);
  ForEachFinestPoint(op, mesh,
                     [&](int node, int triangle, double, const Eigen::Vector3d& gradient,
                         const PiecePoint& point) {
                       // ⟨g, ∇_M b⟩ = ⟨g, ∇b⟩ because g is tangent.
                       load.row(node) +=
                           point.weight * (gradient.transpose() * gradients[triangle]);
                     });
  return load;
}

namespace bspline_detail {

SparseMatrixD HatFunctionCoupling(const BsplineOperator& op) {
  const SurfaceMesh mesh = DescribeSurface(op.triangles, op.positions);
  const BsplineLevel& level = op.finest();
  const NodeIndex index = IndexOf(level);
  const std::vector<SurfacePiece> pieces = ClipSurface(mesh, op.frame, level.depth);
  const TriangleRule rule = CollapsedGaussRule(12);
  std::vector<Eigen::Triplet<double>> triplets;
  std::vector<PiecePoint> points;
  double value[27];
  Eigen::Vector3d gradient[27];
  std::array<int, 27> node{};
  for (size_t p = 0; p < pieces.size(); ++p) {
    const SurfacePiece& piece = pieces[p];
    const Eigen::Vector3i voxel = UnpackKey(piece.voxel);
    if (p == 0 || pieces[p - 1].voxel != piece.voxel) {
      for (int local = 0; local < 27; ++local) {
        const Eigen::Vector3i n = voxel + LocalOffset(local);
        node[local] = index.Find(PackKey(n.x(), n.y(), n.z()));
      }
    }
    // ∫ b φ_k over the piece for its 27 nodes and the triangle's 3 corners.
    Eigen::Matrix<double, 27, 3> local_coupling = Eigen::Matrix<double, 27, 3>::Zero();
    points.clear();
    PiecePoints(piece, rule, points);
    for (const PiecePoint& point : points) {
      EvaluateVoxelNodes(voxel, point.grid, value, gradient);
      for (int local = 0; local < 27; ++local) {
        local_coupling.row(local) += point.weight * value[local] * point.barycentric.transpose();
      }
    }
    for (int local = 0; local < 27; ++local) {
      if (node[local] == kNoNode) continue;
      for (int k = 0; k < 3; ++k) {
        triplets.emplace_back(node[local], op.triangles(piece.triangle, k),
                              local_coupling(local, k));
      }
    }
  }
  SparseMatrixD coupling(level.dimension(), op.positions.rows());
  coupling.setFromTriplets(triplets.begin(), triplets.end());
  return coupling;
}

}  // namespace bspline_detail
}  // namespace dmc

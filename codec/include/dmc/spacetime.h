// The 3D+t spacetime DEC Laplacian of a mesh sequence and its block-tridiagonal solvers
// (dmc_spacetime), after "A 3D+t Laplace operator for temporal mesh sequences"
// (../shared/seeds/spacetime-dec-laplacian-3d+t.txt).
//
// The model. A sequence of F frames of one connectivity (V vertices, E edges, T triangles) is a
// 3-dimensional CW complex in 4D space with the metric diag(α, 1, 1, 1), α > 0: a point is
// (t, x, y, z) and ‖(t, x, y, z)‖² = α·t² + x² + y² + z². Its cells are
//   - the vertices v_i^k (frame k sits at time t_k),
//   - spatial edges v_i^k v_j^k (each frame's edges) and temporal edges v_i^k v_i^{k+1},
//   - triangles of each frame and temporal quadrilaterals (an edge moving from t_k to t_{k+1}),
//   - temporal 3-cells (a triangle moving from t_k to t_{k+1}).
// Between two frames every vertex moves linearly in time, v_i(β) = (1−β)·v_i^k + β·v_i^{k+1},
// β ∈ [0, 1]. A moving cell is measured as the integral over β of its spatial measure at β times
// the temporal length element of the interval: the paper integrates against the 4D length of one
// vertex's temporal edge (its equations 4–5, 26); we use the mean of the 4D temporal edge lengths
// of the cell's vertices, ℓ̄ = mean_i sqrt(α·(t_{k+1} − t_k)² + ‖v_i^{k+1} − v_i^k‖²), which is
// the paper's value whenever the vertices move alike and does not depend on which vertex is
// listed first. Hence
//   temporal quad area    |Q_ij^k| = ℓ̄_ij ∫₀¹ ‖v_j(β) − v_i(β)‖ dβ    (closed form, appendix (a))
//   temporal 3-cell volume |F_f^k| = ℓ̄_f ∫₀¹ Area_f(β) dβ              (Gauss–Legendre, appendix
//   (b))
// Dual cells are barycentric (the paper's §3.4.1): centres are centroids, so
//   ⋆v_i^k        the corner of every incident temporal 3-cell: Σ_f ℓ̄_f/3 ∫ Area_f over the half
//                 interval next to frame k (one half at the first and last frames);
//   ⋆(v_i^k v_j^k) the moving segment edge midpoint → face centroid in every incident face, over
//                 the half intervals next to frame k (four temporal quads, two at the ends);
//                 with SpatialDual::kCircumcentric the segment's signed length is replaced by the
//                 circumcentric one, cot(θ_opposite)/2 · ‖e‖, which makes the α → ∞ limit the
//                 cotangent Laplacian exactly (Property 4.5; barycentric duals give the
//                 barycentric DEC Laplacian in the limit);
//   ⋆(v_i^k v_i^{k+1}) the barycentric region of v_i in the mesh at mid-interval: Σ_f Area_f(½)/3.
//
// The operator. With w the dual-to-primal ratios |⋆e|/|e| of every (spatial or temporal) edge,
// W is the VF×VF weighted graph Laplacian in dmc's sign convention (laplace_operator.h:
// off-diagonals are +w, diagonal −Σw, rows sum to zero) and ⋆0 = diag(|⋆v|) the vertex dual
// volumes:
//   unsymmetrised  Δu = ⋆0⁻¹ · W                   (the paper's Definition 3.3: zero row sums)
//   symmetrised    Δ  = ⋆0^{1/2} Δu ⋆0^{−1/2} = ⋆0^{−1/2} · W · ⋆0^{−1/2}     (Definition 3.6)
// so Δ is symmetric, negative semidefinite, and Δ·⋆0^{1/2}·1 = 0. (The paper writes the diagonal
// of Δ as minus its row sum, eq. 11; that only holds for Δu. We keep the DEC definition.)
// Row and column k·V + i is vertex i of frame k: Δ is block tridiagonal with V×V spatial blocks
// L(k) (the pattern of the mesh's rings plus the diagonal) and diagonal coupling blocks D(k)
// between frames k and k+1, so its nonzero count is exactly F·(V + 2E) + 2·V·(F − 1)
// (SpacetimeNonzeroCount), and it is assembled straight into preallocated compressed storage.
//
// Degenerate input: a vertex in no triangle (or only in zero-area triangles throughout) has no
// dual volume; its rows and columns are stored as explicit zeros. Spatial edges of (near) zero
// length get weight zero and are counted in SpacetimeStats. Nothing produces NaN or infinity
// from finite positions, α > 0 and strictly increasing frame times.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "dmc/laplace_operator.h"
#include "dmc/operator_formulas.h"
#include "dmc/sequence.h"
#include "dmc/sparse_solvers.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

// ---------------------------------------------------------------------------------------------
// Measures of moving cells (the appendix's integrals), exposed for tests and reuse.

// Gauss–Legendre nodes and weights on [−1, 1] for `points` ≥ 1 nodes (Golub–Welsch: the
// eigen-decomposition of the Jacobi matrix). Exact for polynomials of degree ≤ 2·points − 1.
struct GaussLegendreRule {
  Eigen::VectorXd nodes;
  Eigen::VectorXd weights;
};
GaussLegendreRule MakeGaussLegendreRule(int points);

// ∫_{β0}^{β1} ‖a + β·b‖ dβ for vectors a, b ∈ R³, in closed form: with u = β + a·b/‖b‖² and
// c = ‖a × b‖/‖b‖², ‖a + β·b‖ = ‖b‖·sqrt(u² + c²), whose antiderivative is
// ‖b‖·(u·sqrt(u² + c²) + c²·asinh(u/c))/2. When ‖b‖ is tiny next to ‖a‖ the closed form would
// cancel catastrophically, and the (then almost linear) integrand is integrated by 8-point
// Gauss–Legendre instead. This is the length integral of a moving segment whose end points move
// linearly: a = segment at β = 0, b = its change over the interval.
double IntegrateMovingLength(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double beta0,
                             double beta1);

// ∫_{β0}^{β1} Area(p0(β), p1(β), p2(β)) dβ for a triangle whose corners move linearly from
// `start` to `end` (rows are corners), by Gauss–Legendre with `rule` mapped onto [β0, β1]. The
// area is ½·‖β²A + βB + C‖, the square root of a quartic, so no closed form is used (appendix b).
double IntegrateMovingTriangleArea(const Eigen::Matrix3d& start, const Eigen::Matrix3d& end,
                                   double beta0, double beta1, const GaussLegendreRule& rule);

// ---------------------------------------------------------------------------------------------
// The operator.

enum class SpatialDual : uint8_t {
  kBarycentric,  // the paper's choice: centroid duals everywhere; weights are never negative
  kCircumcentric,  // spatial edge duals use cot(θ)/2·‖e‖ (α → ∞ gives the cotangent Laplacian)
};

struct SpacetimeOptions {
  double alpha = 1.0;  // the metric's time weight α > 0
  // Time of each frame, strictly increasing, one per frame. Empty: k / frame_rate when the
  // sequence's frame rate is positive, otherwise k (frames 0..F−1).
  std::vector<double> frame_times;
  SpatialDual spatial_dual = SpatialDual::kBarycentric;
  // Gauss–Legendre nodes per half interval for the moving-triangle integrals; 8 integrates the
  // area of a triangle that does not flip within ~1e-9 relative (tested against Simpson).
  int quadrature_points = 8;
  // Circumcentric duals: cotangents are clamped to ±max_cotangent, as in GeometricOptions.
  double max_cotangent = 57.289961630759425;
};

// Repairs made while measuring; all zero on clean input.
struct SpacetimeStats {
  int short_spatial_edges = 0;  // (edge, frame) pairs of near-zero length: weight set to zero
  int empty_vertex_duals = 0;   // (vertex, frame) pairs without dual volume: zero rows
  int clamped_cotangents = 0;   // circumcentric duals only
};

// Every measure of the complex. Column k of a per-frame matrix is frame k; column k of a
// per-interval matrix is the interval [t_k, t_{k+1}].
struct SpacetimeGeometry {
  int vertex_count = 0;
  int frame_count = 0;
  std::vector<double> frame_times;
  Eigen::MatrixXd spatial_edge_length;      // E × F, ‖v_j^k − v_i^k‖
  Eigen::MatrixXd spatial_edge_dual_area;   // E × F, |⋆(v_i^k v_j^k)|
  Eigen::MatrixXd temporal_edge_length;     // V × (F−1), 4D length of v_i^k v_i^{k+1}
  Eigen::MatrixXd temporal_edge_dual_area;  // V × (F−1), |⋆(v_i^k v_i^{k+1})|
  Eigen::MatrixXd vertex_dual_volume;       // V × F, |⋆v_i^k|
  Eigen::MatrixXd temporal_quad_area;       // E × (F−1), primal |Q_ij^k|
  Eigen::MatrixXd temporal_cell_volume;     // T × (F−1), primal |F_f^k| (0 for a repeated index)
  SpacetimeStats stats;
};

// The built operator.
struct SpacetimeLaplacian {
  int vertex_count = 0;
  int frame_count = 0;
  double alpha = 1.0;
  SparseMatrixD matrix;     // Δ, VF×VF, symmetric, negative semidefinite (see the top)
  SparseMatrixD stiffness;  // W, VF×VF, symmetric, rows sum to zero: the ARAP energy's matrix
  Eigen::VectorXd mass;     // ⋆0, VF dual volumes (index k·V + i)
  SpacetimeGeometry geometry;
};

// Nonzeros of Δ (and W) for a topology and frame count: F·(V + 2E) + 2·V·(F − 1).
int64_t SpacetimeNonzeroCount(const MeshTopology& topology, int frame_count);

// Measures the complex whose frames are `frames` (each V×3) over the triangles of `topology`.
// `triangles` must be the list `topology` was built from. Errors: kInvalidArgument for fewer than
// two frames, α ≤ 0 or non-finite, frame times that are not strictly increasing or do not match
// the frame count, quadrature_points outside [1, 64]; kMismatch for a frame of the wrong size.
StatusOr<SpacetimeGeometry> ComputeSpacetimeGeometry(const MeshTopology& topology,
                                                     const Triangles& triangles,
                                                     std::span<const FramePositionsD> frames,
                                                     const SpacetimeOptions& options);

// Builds Δ, W and ⋆0 from the measures (same errors). TBB-parallel over intervals and frames.
StatusOr<SpacetimeLaplacian> BuildSpacetimeLaplacian(const MeshTopology& topology,
                                                     const Triangles& triangles,
                                                     std::span<const FramePositionsD> frames,
                                                     const SpacetimeOptions& options);
// The whole sequence; frame times default from its frame rate (see SpacetimeOptions).
StatusOr<SpacetimeLaplacian> BuildSpacetimeLaplacian(const MeshSequence& sequence,
                                                     const SpacetimeOptions& options);

// The unsymmetrised operator Δu = ⋆0⁻¹·W (rows of empty duals are zero). Not symmetric.
SparseMatrixD UnsymmetrisedSpacetimeLaplacian(const SpacetimeLaplacian& laplacian);
// The same from the stiffness W and the dual volumes ⋆0 alone (what the operator registry's
// "spacetime" row returns as matrix and mass), and the symmetrised Δ = ⋆0^{−1/2}·W·⋆0^{−1/2}
// (rows and columns of empty duals are zero). Both keep W's sparsity pattern.
SparseMatrixD UnsymmetrisedSpacetimeLaplacian(const SparseMatrixD& stiffness,
                                              const Eigen::VectorXd& mass);
SparseMatrixD SymmetrisedSpacetimeLaplacian(const SparseMatrixD& stiffness,
                                            const Eigen::VectorXd& mass);

// The V×V block (row_frame, column_frame) of a VF×VF matrix; |row_frame − column_frame| ≤ 1 for
// a nonzero block of Δ: L(k) = block (k, k), D(k) = block (k, k+1).
SparseMatrixD SpacetimeBlock(const SparseMatrixD& matrix, int vertex_count, int row_frame,
                             int column_frame);

// ---------------------------------------------------------------------------------------------
// Solving systems on block-tridiagonal matrices.

// Block LDLᵀ of a symmetric positive definite VF×VF matrix A whose off-diagonal V×V blocks are
// diagonal and only couple neighbouring frames (e.g. −Δ, −W, or −W plus soft constraints):
// Λ(1) = A(1,1), Λ(k) = A(k,k) − D(k−1)·Λ(k−1)⁻¹·D(k−1) (the paper's Definition 4.2, Property
// 4.3), each Λ(k) kept as a dense Cholesky factor. The Schur complements Λ(k) fill in, so this
// costs O(F·V³) time and O(F·V²) memory: it suits small blocks; SparseSpdSolver (CHOLMOD) is the
// choice for large meshes (tests/bench/bench_spacetime.cpp measures both).
class BlockTridiagonalSolver {
 public:
  // Fails with kInvalidArgument when the matrix is not (F·block_size)-square, has an entry
  // outside the block-tridiagonal pattern or a non-diagonal coupling block, or is non-finite;
  // kNumericalFailure when a Λ(k) is not positive definite.
  static StatusOr<BlockTridiagonalSolver> Factor(const SparseMatrixD& matrix, int block_size);
  BlockTridiagonalSolver(BlockTridiagonalSolver&&) noexcept;
  BlockTridiagonalSolver& operator=(BlockTridiagonalSolver&&) noexcept;
  ~BlockTridiagonalSolver();

  // Solves A·X = B (B is VF×r) by the block forward and backward sweeps. kMismatch on a row
  // count mismatch, kNumericalFailure on a non-finite result.
  StatusOr<Eigen::MatrixXd> Solve(const Eigen::MatrixXd& rhs) const;

  int block_size() const;
  int block_count() const;

 private:
  struct Impl;
  explicit BlockTridiagonalSolver(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// Spacetime as-rigid-as-possible editing (the paper's §5.3, after Sorkine & Alexa).
//
// A key frame K is edited (handles moved to targets, or the whole key frame replaced); the edit
// spreads over the temporal window [K − W, K + W] (clipped to the sequence) by minimising, over
// the window's vertices p′ ∈ R⁴ (coordinates (√α·t, x, y, z), so the metric is Euclidean) and
// one rotation R_i ∈ SO(4) per spacetime cell (a vertex and its spatial and temporal neighbours),
//   E = Σ_i Σ_{j ~ i} w_ij ‖(p′_i − p′_j) − R_i·(p_i − p_j)‖² + 2λ·Σ_{c constrained} ‖p′_c − t_c‖²
// with w_ij the weights of the spacetime stiffness W and soft constraints (weight λ) on
//   - the handles in the key frame (targets t_c = the edit),
//   - the `fixed` vertices in every window frame (the spatial boundary of the region of
//     interest; targets = input positions),
//   - optionally every vertex of the window's first and last frames when they are not the
//     sequence's ends (the temporal boundary; targets = input positions).
// Local step: R_i from the SVD of the 4×4 covariance Σ_j w_ij (p_i − p_j)(p′_i − p′_j)ᵀ with the
// determinant fixed to +1. Global step: (−W + λ·C)·p′ = b(R) + λ·C·t, factorised once and reused
// by every iteration and every Solve. The first solve uses identity rotations. Iterations stop
// when the largest vertex move is below tolerance × the sequence's bounding-box diagonal. Time
// coordinates are then dropped: every vertex snaps back to its frame. With positive weights
// (barycentric duals) E never increases from one iteration to the next.
//
// Vertices that could float freely are pinned to their input positions, so the system is always
// definite: every spatial component without a handle or fixed vertex when no temporal boundary
// is anchored, and vertices without dual volume (in no triangle).

enum class SpacetimeSolverKind : uint8_t {
  kSparseCholesky,  // SparseSpdSolver (CHOLMOD): the default, scales to large meshes
  kBlockLdlt,       // BlockTridiagonalSolver: dense Schur complements, small meshes only
};

struct SpacetimeArapOptions {
  double alpha = 1.0;
  int key_frame = 0;
  int window = 2;  // ≥ 1: frames [key − window, key + window] ∩ [0, F − 1] are edited
  std::vector<double> frame_times;  // as SpacetimeOptions::frame_times (whole sequence)
  SpatialDual spatial_dual = SpatialDual::kBarycentric;
  bool anchor_temporal_boundary = true;
  // λ = constraint_weight × the mean diagonal of −W: large enough that handles land within a
  // fraction of a percent of their targets, small enough to keep the system well conditioned.
  double constraint_weight = 1e3;
  double tolerance = 1e-5;  // largest vertex move per iteration, relative to the bbox diagonal
  int max_iterations = 100;
  SpacetimeSolverKind solver = SpacetimeSolverKind::kSparseCholesky;
};

// Which vertices are constrained. Handles live in the key frame; `fixed` in every window frame.
struct SpacetimeArapConstraints {
  std::vector<int32_t> handles;
  std::vector<int32_t> fixed;
};

struct SpacetimeArapResult {
  MeshSequence sequence;                // the input with the window's frames replaced
  int first_frame = 0, last_frame = 0;  // the window
  int iterations = 0;                   // global steps after the initial identity-rotation solve
  bool converged = false;
  double last_move = 0.0;  // largest vertex move of the last iteration (absolute)
  // E after each local step: energies[0] with the rotations fitted to the initial solve, then
  // one value per iteration. Non-increasing for non-negative weights.
  std::vector<double> energies;
  double max_handle_error = 0.0;  // largest distance of a handle from its target (soft)
};

// The prepared editor: operator built and system factorised once per (sequence, constraints,
// options); Solve may then be called for any number of handle targets.
class SpacetimeArapEditor {
 public:
  // kInvalidArgument: bad options (α ≤ 0, window < 1, key frame outside the sequence, a window
  // of fewer than two frames, tolerance ≤ 0), a vertex index outside [0, V), a vertex both
  // handle and fixed, no handle at all; the operator's errors; kNumericalFailure if the system
  // cannot be factorised.
  static StatusOr<SpacetimeArapEditor> Create(const MeshSequence& sequence,
                                              const SpacetimeArapConstraints& constraints,
                                              const SpacetimeArapOptions& options);
  SpacetimeArapEditor(SpacetimeArapEditor&&) noexcept;
  SpacetimeArapEditor& operator=(SpacetimeArapEditor&&) noexcept;
  ~SpacetimeArapEditor();

  // Handle targets in the key frame, |handles|×3 in the order given to Create (kMismatch
  // otherwise; kInvalidArgument when not finite).
  StatusOr<SpacetimeArapResult> Solve(const Eigen::MatrixXd& handle_targets) const;

  int first_frame() const;
  int last_frame() const;
  int unknowns() const;  // V × window frames
  const SpacetimeLaplacian& laplacian() const;

 private:
  struct Impl;
  explicit SpacetimeArapEditor(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dmc

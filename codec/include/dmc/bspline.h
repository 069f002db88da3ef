// The restricted B-spline Laplace–Beltrami operator (Chuang, Luo, Brown, Rusinkiewicz & Kazhdan,
// "Estimating the Laplace-Beltrami Operator by Restricting 3D Functions", SGP 2009) and its
// octree multigrid solver (dmc_bspline).
//
// Function space: the mesh's bounding cube is split into a grid of 2^d × 2^d × 2^d voxels (the
// depth-d level of an octree). Every voxel n carries the degree-2 (second order) tensor-product
// B-spline b_n(p) = B(p_x/h − n_x − ½)·B(p_y/h − n_y − ½)·B(p_z/h − n_z − ½) in grid units, with
// h the voxel width and B the centred quadratic B-spline of support 3 (so b_n is supported on the
// 3×3×3 voxels around n). Only nodes whose support meets the surface in positive area are kept
// (the pruned octree O^M of the paper); their restrictions to the surface are the elements. The
// kept functions sum to one on the surface, so constants are represented exactly.
//
// Matrices, with the repository's sign convention (laplace_operator.h: negative diagonal):
//     L_ij = −∫_M ⟨∇_M b_i, ∇_M b_j⟩,   D_ij = ∫_M b_i b_j,
// with ∇_M b = ∇b − ⟨∇b, N⟩N. L is symmetric negative semidefinite with L·1 = 0; D is symmetric
// positive semidefinite and 1ᵀD1 = area(M). Integration is exact: every triangle is split at the
// voxel planes into pieces that lie in one voxel, where the restricted elements are polynomials
// of degree 6, and each piece is integrated with a collapsed Gauss–Legendre rule exact for degree
// 12 (the degree of b_i b_j). The Monte Carlo option sums over area-uniform random surface
// samples instead (the paper's "summing over point samples").
//
// Caveat of the method (paper §5.5, and inherent to restricting 3D functions): where the surface
// is flat on the scale of a voxel, the restricted elements are linearly dependent, so D and L
// share (near) null vectors whose restriction to the surface is (almost) zero. They do not change
// any function on the surface; the eigen solver regularises them away (see
// ComputeGeneralizedSpectrum) and the multigrid simply leaves them alone.
//
// Multigrid: depths coarsest_depth … depth each get their own pruned node set and matrices,
// integrated on their own voxel grid (setup O(N·d) for N triangles); the prolongation from depth
// l to l+1 is the tensor product of the 1D refinement stencil ¼(1 3 3 1), restriction is its
// transpose. Because the spaces are nested and the integration exact, Pᵀ L_{l+1} P = L_l (and the
// same for D) up to rounding. Cycles relax with Gauss–Seidel (forward before, backward after the
// coarse correction, so a cycle is a symmetric operator) and solve the coarsest level directly.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>
#include <vector>

#include "dmc/laplace_operator.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

enum class BsplineIntegration : uint8_t {
  kCubature,    // exact: triangles split at voxel planes, a rule exact for the polynomial degree
  kMonteCarlo,  // area-uniform random surface samples (same samples at every depth)
};

struct BsplineOptions {
  int depth = 5;           // finest octree depth d: 2^d voxels per axis; 1 ≤ d ≤ 10
  int coarsest_depth = 2;  // first multigrid level (clamped to [1, depth])
  BsplineIntegration integration = BsplineIntegration::kCubature;
  // Cubature: polynomial degree integrated exactly per piece (n×n collapsed Gauss points with
  // n = ⌈(degree + 2)/2⌉). 12 makes mass and stiffness exact; lower is faster and approximate.
  int cubature_degree = 12;
  // Monte Carlo: number of surface samples; 0 chooses 64 per voxel of the finest grid the surface
  // meets (estimated as area / h²).
  int64_t monte_carlo_samples = 0;
  uint64_t seed = 1;  // Monte Carlo sampling only
};

// Voxel grid placement: world point p has grid coordinates (p − origin) / cube_size · 2^depth.
struct BsplineFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // minimum corner of the bounding cube
  double cube_size = 1.0;                            // edge of the bounding cube (world units)
};

// One level of the hierarchy.
struct BsplineLevel {
  int depth = 0;
  // Kept nodes, sorted (x, then y, then z). Coordinates are voxel indices at this depth and may be
  // −1 or 2^depth: functions centred just outside the cube still reach into it.
  std::vector<Eigen::Vector3i> nodes;
  SparseMatrixD laplacian;     // L, n×n, see the top of this file
  SparseMatrixD mass;          // D, n×n
  SparseMatrixD prolongation;  // n_{l+1}×n_l into the next finer level; empty at the finest
  int64_t pieces = 0;          // triangle pieces (cubature) or samples integrated at this level
  int dimension() const { return static_cast<int>(nodes.size()); }
};

struct BsplineOperator {
  BsplineFrame frame;
  std::vector<BsplineLevel> levels;  // coarsest first; levels.back() is depth d
  // V×n_d: vertex values = evaluation · η for element coefficients η (rows sum to one on every
  // vertex referenced by a triangle, zero rows on unreferenced vertices).
  SparseMatrixD evaluation;
  double area = 0.0;  // total surface area (world units)
  // The mesh the operator was built on (kept to integrate per-vertex fields later).
  Triangles triangles;
  FramePositionsD positions;

  const BsplineLevel& finest() const { return levels.back(); }
  int dimension() const { return finest().dimension(); }
};

// Builds the pruned octree, the elements and L, D, P at every depth from coarsest_depth to depth.
// kInvalidArgument for a depth outside [1, 10], a cubature degree outside [1, 40], an index out of
// range, a non-finite position, or a mesh of zero area.
StatusOr<BsplineOperator> BuildBsplineOperator(const Triangles& triangles,
                                               const FramePositionsD& positions,
                                               const BsplineOptions& options = {});

// Values of the finest elements at arbitrary points (rows: points, columns: elements). Points
// outside the bounding cube get the values of the nearest voxel's polynomials.
SparseMatrixD BsplineEvaluationMatrix(const BsplineOperator& op, const FramePositionsD& points);

// Load vectors for per-vertex fields f (V×c, linear inside each triangle):
//   values:    γ_i = ∫ f b_i                       (n×c)
//   gradients: ψ_i = ∫ ⟨g, ∇_M b_i⟩ with g = s·∇_M f   (n×c; s = gradient_scale)
// integrated exactly with the finest level's cubature (both are polynomial per piece).
// kMismatch when the field's row count is not the operator's vertex count.
StatusOr<Eigen::MatrixXd> IntegrateValueLoad(const BsplineOperator& op,
                                             const Eigen::MatrixXd& vertex_values);
StatusOr<Eigen::MatrixXd> IntegrateGradientLoad(const BsplineOperator& op,
                                                const Eigen::MatrixXd& vertex_values,
                                                double gradient_scale = 1.0);

// ---------------------------------------------------------------------------------------------
// Multigrid for A = stiffness_weight·(−L) + mass_weight·D at every level.

enum class MultigridCycle : uint8_t { kV, kW };

struct MultigridOptions {
  MultigridCycle cycle = MultigridCycle::kW;
  int pre_smoothing = 2;   // forward Gauss–Seidel sweeps before the coarse correction
  int post_smoothing = 2;  // backward sweeps after it
  int max_cycles = 50;
  double relative_tolerance = 1e-8;  // stop when ‖b − A x‖ ≤ tolerance · ‖b‖
};

struct MultigridReport {
  int cycles = 0;
  double initial_residual = 0.0;  // ‖b − A x0‖
  double final_residual = 0.0;
  std::vector<double> residual_history;  // after each cycle
  bool converged = false;
};

class BsplineMultigrid {
 public:
  // stiffness_weight, mass_weight ≥ 0 and not both zero. With mass_weight = 0 the system is the
  // pure Poisson problem, singular with the constants in its null space: the right-hand side must
  // then integrate to zero (Σ b_i = 0), and the coarse solve is regularised by 1e-12·mean
  // diagonal so it stays defined. Factors the coarsest level once (kNumericalFailure if it fails).
  static StatusOr<BsplineMultigrid> Create(const BsplineOperator& op, double stiffness_weight,
                                           double mass_weight);
  BsplineMultigrid(BsplineMultigrid&&) noexcept;
  BsplineMultigrid& operator=(BsplineMultigrid&&) noexcept;
  ~BsplineMultigrid();

  // One cycle on the finest level, improving x in place (x.size() = rhs.size() = dimension).
  void Cycle(const Eigen::VectorXd& rhs, Eigen::VectorXd& x, const MultigridOptions& options) const;
  // Cycles from x (use zeros for no initial guess) until the tolerance or max_cycles. kMismatch
  // on a size mismatch; kNumericalFailure when the residual becomes non-finite.
  StatusOr<MultigridReport> Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x,
                                  const MultigridOptions& options = {}) const;

  const SparseMatrixD& system(int level) const;  // A at levels[level] (0 = coarsest)
  int level_count() const;
  int dimension() const;

 private:
  struct Impl;
  explicit BsplineMultigrid(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// ---------------------------------------------------------------------------------------------
// Spectra.

// The `count` smallest eigenpairs of K η = λ M η for symmetric positive semidefinite K (e.g. −L)
// and symmetric positive semidefinite M (e.g. D, or a diagonal vertex mass), ascending; the zero
// mode of a closed surface comes first. Shift-invert Lanczos (Spectra) with a negative shift.
// Both matrices are regularised by 1e-10·(mean diagonal)·I before factoring, so vectors null in
// both (linearly dependent restricted elements) land near the top of the spectrum instead of
// making the pencil singular; real eigenvalues move by a relative ~1e-10. Eigenvectors are
// M-orthonormal. kInvalidArgument when count < 1 or count ≥ n, kNumericalFailure when the
// factorisation or Lanczos fails.
struct GeneralizedSpectrum {
  Eigen::VectorXd eigenvalues;   // ascending, ≥ −rounding
  Eigen::MatrixXd eigenvectors;  // n×count
};
StatusOr<GeneralizedSpectrum> ComputeGeneralizedSpectrum(const SparseMatrixD& stiffness,
                                                         const SparseMatrixD& mass, int count);

// The B-spline operator's spectrum: −L η = λ D η at the finest level, so λ_k ≥ 0 (on the unit
// sphere: 0, 2 ×3, 6 ×5, 12 ×7, … = l(l+1) with multiplicity 2l+1).
StatusOr<GeneralizedSpectrum> ComputeBsplineSpectrum(const BsplineOperator& op, int count);

// Spectrum of an operator from the registry: −L η = λ M η with M its mass_matrix (kElement
// operators such as "bspline": the same pencil as ComputeBsplineSpectrum), else its diagonal mass
// (cotan-sym: vertex areas; spacetime: ⋆0), else the identity. kUnsupported for a non-symmetric
// operator.
StatusOr<GeneralizedSpectrum> LaplacianSpectrum(const LaplaceOperator& op, int count);

// ---------------------------------------------------------------------------------------------
// Per-vertex form. The registry row "bspline" is the element operator itself (L, D and the
// evaluation matrix, OperatorDomain::kElement); this is its pull-back to a V×V matrix for code
// that needs per-vertex operators.

// The vertex operator L_V = Rᵀ L R with mass m = Rᵀ D 1, where R (n×V) is the lumped L² projection
// from the mesh's piecewise-linear functions to the elements, R_iv = ∫ b_i φ_v / ∫ b_i (φ_v the
// hat function of v; rows of R sum to one, so R maps constants to constants). L_V is symmetric,
// negative semidefinite, has zero row sums, and m⁻¹·L_V·x approximates Δ_M x. Its stencil is
// wider than the one-ring (vertices within about five voxels couple), so `weights` stays empty:
// the matrix is the operator. Triangles are recovered from the topology's edge/opposite table
// (orientation is irrelevant here). depth 0 chooses the finest depth whose voxel is at least the
// mean edge length (clamped to [2, 7]). Errors as BuildBsplineOperator, plus kMismatch when the
// position count is not the topology's vertex count.
StatusOr<LaplaceOperator> BuildBsplineVertexOperator(const MeshTopology& topology,
                                                     const FramePositionsD& positions,
                                                     int depth = 0);

// The triangles of a topology, recovered from its edges and their opposite vertices (sorted
// corner triples, de-duplicated): what the operator registry's factories, which receive only the
// topology, build from. Orientation and triangles beyond the second on a non-manifold edge are
// lost; areas, dual cells and the B-spline integrals do not depend on either.
Triangles TrianglesFromTopology(const MeshTopology& topology);

// The depth rule of BuildBsplineVertexOperator for a mesh: voxel ≥ mean edge length, in [2, 7].
int AutomaticBsplineDepth(const Triangles& triangles, const FramePositionsD& positions);

}  // namespace dmc

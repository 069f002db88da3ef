// Discrete Laplace operators on a fixed-connectivity mesh: assembly from weights, the geometric and
// combinatorial weight formulas, the normal-equation solver, and (implemented in dmc_fitting) the
// data-dependent Laplacian fits and the operator registry.
//
// ONE sign convention, used by every operator and by the codec decoder:
//
//     δ = L·X,   L_ij = w_ij for every (directed) edge i→j,   L_ii = −Σ_j w_ij,   else 0,
//
// so δ_i = Σ_j w_ij (x_j − x_i) (the thesis's equation 2.3). Every row sums to zero (up to the
// rounding of one sum), constants lie in the null space, and δ is translation invariant.
// Off-diagonal entries ARE the weights: positive weights mean positive off-diagonals and a
// negative diagonal (this is −1 times the usual positive semi-definite "D − A" graph Laplacian).
//
//   name        weights w_ij                               symmetric  diagonal L_ii
//   kirchhoff   1                                          yes        −deg(i)
//   tutte       1/deg(i)                                   no         −1 (unit sum)
//   cotan       k_ij / Σ_j k_ij                            no         −1 (unit sum)
//   cotan-area  k_ij / A_i  (mixed Voronoi area A_i)       no         −Σ_j k_ij / A_i
//   cotan-sym   k_ij                                       yes        −Σ_j k_ij
//   mean-value  Floater's weights / their row sum          no         −1 (unit sum)
//   ddl         fitted, one per edge, rows unit sum        yes        −1 (unit sum)
//   ddl-asym    fitted, one per directed edge, unit sum    no         −1 (unit sum)
//
// with k_ij = (cot α_ij + cot β_ij)/2 over the (one or two) angles opposite edge ij. Isolated
// vertices (no edge) have an all-zero row everywhere, so "unit sum" holds on every other row.
// cotan-area applied to positions approximates the mean-curvature normal: δ_i ≈ −2 H_i n_i, so on
// a sphere of radius R, ‖δ_i‖/2 ≈ 1/R. The mass matrix (diagonal, mixed Voronoi areas) is
// provided by the cotangent operators only; M⁻¹·(cotan-sym) = cotan-area.
//
// Weight layouts (the order the codec transmits weights in):
//   kPerEdge          one value per undirected edge, in MeshTopology::edges order (w_ij = w_ji).
//   kPerDirectedEdge  one value per directed edge i→j, in the CSR order of the topology's rings:
//                     the weight of i→ring_neighbors[k] is values[k], k in
//                     [ring_offsets[i], ring_offsets[i+1]).
//
// Robustness of the geometric formulas: cotangents are clamped to ±GeometricOptions::max_cotangent
// (default cot 1° ≈ 57.29), zero-area triangles contribute nothing to areas and their angles are
// clamped, rows whose normalising sum is not safely positive fall back to Tutte weights, and every
// such repair is counted in OperatorStats. No formula ever produces NaN or infinity from finite
// input positions.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"
#include "dmc/wire_ids.h"

namespace dmc {

using SparseMatrixD = Eigen::SparseMatrix<double>;  // column-major, int storage indices

// ---------------------------------------------------------------------------------------------
// Weights and assembly (dmc_operators; decoder side)

enum class WeightLayout : uint8_t {
  kPerEdge,          // symmetric operator: values[e] = w_ij = w_ji for edge e = (i, j)
  kPerDirectedEdge,  // values[k] = weight of i → ring_neighbors[k] (CSR ring order)
};

struct OperatorWeights {
  WeightLayout layout = WeightLayout::kPerEdge;
  std::vector<double> values;
};

// Repairs and diagnostics of an operator build. All counts are zero on a clean, well-shaped mesh.
struct OperatorStats {
  int clamped_cotangents = 0;    // cot (mean-value: tan(α/2)) beyond max_cotangent: slivers
  int degenerate_triangles = 0;  // triangles of (near) zero area in the reference frame
  int fallback_rows = 0;         // rows whose normalising sum was ≤ 0 or tiny: Tutte row used
  int clamped_areas = 0;         // vertices whose Voronoi area was floored (cotan-area)
  int isolated_vertices = 0;     // all-zero rows
  // DDL fits only.
  int dropped_constraints = 0;    // dependent unit-sum constraints dropped (bipartite components)
  int inconsistent_rows = 0;      // rows whose unit sum is unattainable (unbalanced bipartite)
  int solver_iterations = 0;      // augmented-Lagrangian iterations of the symmetric fit
  double fit_residual = 0.0;      // Σ_i ‖δ_i‖² on the fitted trajectories
  double constraint_error = 0.0;  // max_i |Σ_j w_ij − 1| over constrained rows
  // spacetime only (SpacetimeStats).
  int short_spatial_edges = 0;  // (edge, frame) pairs of near-zero length: weight set to zero
  int empty_vertex_duals = 0;   // (vertex, frame) pairs without dual volume: zero rows
};

// What the rows and columns of LaplaceOperator::matrix stand for. Every operator with a wire ID
// (everything the codec and the per-vertex processing methods use) is kVertex; the other two are
// registry rows for analysis and their own solvers. The sign convention above holds in every
// domain: off-diagonals are the couplings, rows sum to zero, and a symmetric matrix is negative
// semidefinite.
enum class OperatorDomain : uint8_t {
  kVertex,     // V×V: row i is mesh vertex i
  kSpacetime,  // V·F×V·F: row k·V + i is vertex i in frame k (F = LaplaceOperator::frame_count);
               // block tridiagonal (dmc/spacetime.h)
  kElement,  // N×N: row n is basis function n of a function space other than the mesh's hat
             // functions (the B-spline elements of dmc/bspline.h); N does not depend on V
};

// A built operator: the matrix, the weights it was assembled from, and optionally a mass matrix.
// The mass turns the stiffness-like `matrix` into the pointwise operator: M⁻¹·matrix (e.g.
// cotan-sym → cotan-area), and the generalized problem −matrix·η = λ·M·η gives its spectrum.
struct LaplaceOperator {
  std::string name;         // registry name, e.g. "cotan"
  SparseMatrixD matrix;     // square, size and meaning given by `domain`; sign convention above
  OperatorWeights weights;  // kVertex one-ring operators: matrix == AssembleLaplacian(topology,
                            // weights); empty values when the matrix is not a one-ring assembly
  Eigen::VectorXd mass;     // diagonal mass matrix, one entry per matrix row (vertex areas; dual
                            // volumes ⋆0 for kSpacetime); empty when not defined or not diagonal
  bool symmetric = false;   // matrix is symmetric by construction
  bool unit_sum = false;    // every non-isolated row has diagonal −1
  OperatorStats stats;

  OperatorDomain domain = OperatorDomain::kVertex;
  int frame_count = 1;  // kSpacetime: the F frames the matrix spans (V·F rows); 1 otherwise
  // kElement only (empty otherwise):
  SparseMatrixD mass_matrix;  // N×N, symmetric positive semidefinite, not diagonal (Gram matrix
                              // ∫ b_i b_j); replaces `mass` in M⁻¹·matrix and the spectrum
  SparseMatrixD evaluation;   // V×N: vertex values = evaluation · element coefficients; every row
                              // of a vertex in a triangle sums to one (partition of unity)
};

// The one assembly routine: off-diagonals = weights, diagonal = −(sum of the row's off-diagonals),
// summed in ring order so every caller (encoder, decoder, tools) gets bit-identical matrices from
// identical weights. Fails with kMismatch if the value count does not match the layout (E or 2E)
// and kInvalidArgument on a non-finite weight. Zero weights are stored as explicit entries, so the
// sparsity pattern is always the mesh's (rings plus diagonal).
StatusOr<SparseMatrixD> AssembleLaplacian(const MeshTopology& topology,
                                          const OperatorWeights& weights);

// Index k into the topology's ring arrays of the directed edge i → j, or -1 if (i, j) is no edge.
int RingSlot(const MeshTopology& topology, int i, int j);

// ---------------------------------------------------------------------------------------------
// Geometric and combinatorial weight formulas (dmc_operators; decoder side)

struct GeometricOptions {
  // Cotangents are clamped to [−max_cotangent, max_cotangent]. The default, cot(1°) ≈ 57.29,
  // only touches angles below 1° or above 179° (slivers); the count is reported.
  double max_cotangent = 57.289961630759425;
  // A row whose normalising sum (Σ k_ij for cotan, Σ of mean-value weights) is below
  // min_row_sum_ratio × Σ |k_ij| is treated as degenerate and replaced by the Tutte row.
  double min_row_sum_ratio = 1e-6;
};

// Per-edge k_ij = (cot α_ij + cot β_ij)/2 (one term on boundary edges), clamped as above.
// `positions` is V×3. `stats` (may be null) receives clamping counts.
std::vector<double> CotangentEdgeWeights(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options = {},
                                         OperatorStats* stats = nullptr);

// Mixed Voronoi vertex areas (Meyer et al. 2003): the Voronoi region inside non-obtuse
// triangles, and area/2 (obtuse corner) or area/4 (other corners) inside obtuse ones. Each
// triangle is visited through the topology's edge/opposite table, so triangles beyond the
// second on a non-manifold edge are not counted.
// Degenerate (zero-area) triangles contribute nothing.
Eigen::VectorXd MixedVoronoiAreas(const MeshTopology& topology, const FramePositionsD& positions);

// Floater's mean value weights per directed edge, not yet normalised:
// w_ij = (tan(α⁻/2) + tan(α⁺/2)) / ‖x_j − x_i‖ with α± the angles at i of the triangles on edge
// ij, tan(α/2) capped at max_cotangent. Non-negative; edges of (near) zero length use a floored
// length.
std::vector<double> MeanValueDirectedWeights(const MeshTopology& topology,
                                             const FramePositionsD& positions,
                                             const GeometricOptions& options = {},
                                             OperatorStats* stats = nullptr);

// Directed Tutte weights 1/deg(i); the reference the DDL regulariser pulls toward by default.
std::vector<double> TutteDirectedWeights(const MeshTopology& topology);

// Scales each row of directed weights to unit sum. Rows whose sum is ≤ min_row_sum_ratio × Σ|w|
// get Tutte weights instead (counted in stats->fallback_rows).
void NormalizeRowsToUnitSum(const MeshTopology& topology, std::vector<double>& directed,
                            double min_row_sum_ratio, OperatorStats* stats);

// Builders of the non-fitted operators. Geometric ones take one frame of positions (V×3); for a
// sequence pass a reference frame such as MeanFrame(). Fail with kMismatch on a size mismatch.
StatusOr<LaplaceOperator> BuildKirchhoff(const MeshTopology& topology);
StatusOr<LaplaceOperator> BuildTutte(const MeshTopology& topology);
StatusOr<LaplaceOperator> BuildCotan(const MeshTopology& topology, const FramePositionsD& positions,
                                     const GeometricOptions& options = {});
StatusOr<LaplaceOperator> BuildCotanArea(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options = {});
StatusOr<LaplaceOperator> BuildCotanSym(const MeshTopology& topology,
                                        const FramePositionsD& positions,
                                        const GeometricOptions& options = {});
StatusOr<LaplaceOperator> BuildMeanValue(const MeshTopology& topology,
                                         const FramePositionsD& positions,
                                         const GeometricOptions& options = {});

// Builds a LaplaceOperator from already known weights (e.g. DDL weights decoded from a stream):
// assembles the matrix and fills symmetric / unit_sum from the layout and name.
StatusOr<LaplaceOperator> OperatorFromWeights(std::string name, const MeshTopology& topology,
                                              OperatorWeights weights, bool unit_sum);

// What a decoder needs to rebuild the operator a stream names: combinatorial operators need
// nothing, geometric ones `reference_frame` (V×3), DDL ones `weights` in their layout (kPerEdge
// for kDdl, kPerDirectedEdge for kDdlAsym). Missing input → kInvalidArgument; unknown ID →
// kNotFound listing the known IDs.
StatusOr<LaplaceOperator> RebuildOperator(OperatorId id, const MeshTopology& topology,
                                          const FramePositionsD* reference_frame,
                                          const OperatorWeights* weights);

// Registry name of a wire ID ("ddl"), or "" for an unknown ID.
std::string_view OperatorIdName(OperatorId id);

// Mean over frames of every vertex position (V×3, double).
FramePositionsD MeanFrame(const MeshSequence& sequence);

// ---------------------------------------------------------------------------------------------
// Normal equations: factor once, solve many (dmc_operators; decoder side)

// N = L̃ᵀL̃ for L̃ = [L; anchor_weight·P], P selecting the anchor rows: N = LᵀL + anchor_weight²·
// Σ_a e_a e_aᵀ. Sparse (2-ring pattern), symmetric; positive definite when every connected
// component holds an anchor and L has rank V − components.
SparseMatrixD BuildNormalMatrix(const SparseMatrixD& laplacian, std::span<const int32_t> anchors,
                                double anchor_weight = 1.0);

enum class SolverBackend : uint8_t {
  kAuto,            // the measured faster one for Laplacian normal matrices (see solvers/)
  kCholmod,         // CHOLMOD supernodal LLᵀ through Eigen's CholmodSupport
  kSimplicialLdlt,  // Eigen::SimplicialLDLT (AMD ordering)
};
std::string_view SolverBackendName(SolverBackend backend);

// Fill-reducing ordering of the CHOLMOD backend (SimplicialLDLT always uses AMD).
enum class SolverOrdering : uint8_t {
  kAuto,   // nested dissection (METIS) from 30000 unknowns on, AMD below
  kAmd,    // approximate minimum degree: cheapest analysis
  kMetis,  // nested dissection: less fill on large mesh-like graphs, costlier analysis
};

struct SolverOptions {
  SolverBackend backend = SolverBackend::kAuto;
  SolverOrdering ordering = SolverOrdering::kAuto;
  // The factorisation is rejected as numerically singular when its smallest pivot is below
  // min_pivot_ratio × its largest (an estimate of 1/cond(N)); a semidefinite N (an unanchored
  // component) lands near 1e-16 while real Laplacian normal matrices stay far above.
  double min_pivot_ratio = 1e-13;
  // A solve is rejected when ‖N·X − B‖_F > max_relative_residual × ‖B‖_F or X is non-finite.
  double max_relative_residual = 1e-6;
};

// Factorisation of a symmetric positive definite sparse matrix, reused for many right-hand
// sides. Move-only. Failures: kInvalidArgument (not square, empty, non-finite entries),
// kNumericalFailure (not positive definite or numerically singular: never a garbage factor).
class SparseSpdSolver {
 public:
  static StatusOr<SparseSpdSolver> Factor(const SparseMatrixD& matrix,
                                          const SolverOptions& options = {});
  SparseSpdSolver(SparseSpdSolver&&) noexcept;
  SparseSpdSolver& operator=(SparseSpdSolver&&) noexcept;
  ~SparseSpdSolver();

  // Solves N·X = B for all columns of B (n×r) at once. kMismatch on a row-count mismatch,
  // kNumericalFailure if the result is non-finite or its residual exceeds the tolerance.
  StatusOr<Eigen::MatrixXd> Solve(const Eigen::MatrixXd& rhs) const;

  SolverBackend backend() const;
  int size() const;
  double pivot_ratio() const;  // smallest / largest pivot of the factor

 private:
  struct Impl;
  explicit SparseSpdSolver(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Least-squares reconstruction from differential coordinates and anchors, the decoder's core:
// X = argmin ‖L·X − Δ‖² + anchor_weight²·‖P·X − A‖², i.e. N·X = Lᵀ·Δ + anchor_weight²·Pᵀ·A.
// Create() checks that every connected component has an anchor (otherwise N is singular:
// kNumericalFailure naming the component) and factors N once.
class AnchoredLaplacianSolver {
 public:
  static StatusOr<AnchoredLaplacianSolver> Create(const MeshTopology& topology,
                                                  const SparseMatrixD& laplacian,
                                                  std::vector<int32_t> anchors,
                                                  double anchor_weight = 1.0,
                                                  const SolverOptions& options = {});

  // delta: V×r differential coordinates, anchor_values: (anchor count)×r. Returns V×r.
  StatusOr<Eigen::MatrixXd> Solve(const Eigen::MatrixXd& delta,
                                  const Eigen::MatrixXd& anchor_values) const;

  const std::vector<int32_t>& anchors() const { return anchors_; }

 private:
  AnchoredLaplacianSolver(SparseMatrixD laplacian_transpose, std::vector<int32_t> anchors,
                          double anchor_weight, SparseSpdSolver solver);
  SparseMatrixD laplacian_transpose_;
  std::vector<int32_t> anchors_;
  double anchor_weight_;
  SparseSpdSolver solver_;
};

// ---------------------------------------------------------------------------------------------
// Data-dependent Laplacian fits and the operator registry (dmc_fitting: encoder and processing
// side only; the decoder never links these).

// Reference operator of the DDL Tikhonov term.
enum class DdlReference : uint8_t { kTutte, kCotan };

struct DdlOptions {
  // Tikhonov weight μ ≥ 0, dimensionless. The fit minimises
  //   Σ_i ‖Σ_j w_ij (c_j − c_i)‖² + μ·s·Σ_{i→j} (w_ij − ref_ij)²
  // over directed edges, with s the mean of ‖c_j − c_i‖² over directed edges, so μ means the same
  // thing whatever the data's scale or rank: μ = 1 makes a unit weight deviation cost as much as
  // one typical squared edge residual. codec-notes found μ ≈ 1e-2..3e-2 toward Tutte to trade
  // a slightly larger residual for a much better conditioned normal matrix.
  double mu = 0.0;
  DdlReference reference = DdlReference::kTutte;
  // Always added on top of μ (same form): makes the problem strictly convex when the data do not
  // determine every weight (static or planar data, low rank), picking the solution nearest the
  // reference. Small enough not to move a well-determined fit measurably.
  double min_mu = 1e-9;
};

// Where an operator's inputs come from. Geometric operators use `reference_frame`; DDL operators
// use `trajectories` (V×r: one row per vertex; positions of all frames, PCA coefficients, or a
// single frame) and `reference_frame` only for a cotangent Tikhonov reference.
struct OperatorSource {
  std::optional<FramePositionsD> reference_frame;
  std::optional<Eigen::MatrixXd> trajectories;
};

// One frame: reference frame = the frame, trajectories = its V×3 positions.
OperatorSource SourceFromFrame(const FramePositionsD& positions);
// A whole sequence: reference frame = frame `reference_frame_index`, or the mean frame when it
// is negative; trajectories = all frames' positions, V×3F with column 3f + axis.
OperatorSource SourceFromSequence(const MeshSequence& sequence, int reference_frame_index = -1);
// Reduced trajectories (e.g. PCA coefficients, V×r); add a reference frame for geometric ones.
OperatorSource SourceFromTrajectories(Eigen::MatrixXd trajectories);

// Options of the spacetime row (the full set is dmc/spacetime.h's SpacetimeOptions).
struct SpacetimeOperatorOptions {
  double alpha = 1.0;       // time weight α > 0 of the 4D metric diag(α, 1, 1, 1)
  double frame_rate = 0.0;  // frame k sits at time k / frame_rate; ≤ 0: at time k
};

// Options of the bspline row (the full set is dmc/bspline.h's BsplineOptions).
struct BsplineOperatorOptions {
  int depth = 0;  // octree depth in [1, 10]; 0 picks the depth whose voxel is about one mean
                  // edge long (AutomaticBsplineDepth, in [2, 7])
};

struct OperatorOptions {
  GeometricOptions geometric;
  DdlOptions ddl;
  SolverOptions solver;  // backend of the symmetric DDL fit's sparse factorisations
  SpacetimeOperatorOptions spacetime;
  BsplineOperatorOptions bspline;
  // BuildOperator refuses (kUnsupported, naming the operator's domain) to build an operator whose
  // domain is not kVertex unless this is set, so code written for V×V matrices gets a clear error
  // instead of a matrix of another size. Callers that read LaplaceOperator::domain set it.
  bool allow_any_domain = false;
};

// Symmetric DDL: one weight per edge (kPerEdge), minimising the objective above subject to
// Σ_j w_ij = 1 for every non-isolated vertex. Solved by an augmented Lagrangian on the E×E
// system QᵀQ + μ-terms + ρ·AᵀA (assembled directly from scalar products of trajectory
// differences, TBB-parallel; Q is never formed), factored once, followed by an exact projection
// onto the constraint set through the V×V matrix A·Aᵀ, so constraints hold to ~1e-14.
// Rank deficiency: the unit-sum system A·w = 1 (A the V×E vertex–edge incidence) has full row
// rank on every component containing an odd cycle — every triangle is one, so every component of
// a triangle mesh. Only components made of degenerate triangles can be bipartite; there the rows
// of A are dependent, one constraint per such component is dropped (stats.dropped_constraints),
// and if the component's two colour classes differ in size no symmetric unit-sum weights exist:
// the dropped vertex's row then misses unit sum (stats.inconsistent_rows). Degree-1 vertices pin
// their edge to 1; degree-2 vertices and strips simply leave fewer free weights; data that do not
// determine all weights (low rank, planar, static) are resolved by min_mu toward the reference.
// Fails with kInvalidArgument when trajectories are missing or have the wrong row count.
StatusOr<LaplaceOperator> FitDdlSymmetric(const MeshTopology& topology,
                                          const OperatorSource& source,
                                          const OperatorOptions& options = {});

// Asymmetric DDL: one weight per directed edge (kPerDirectedEdge), each row unit sum. Decouples
// per vertex into a deg×deg equality-constrained least-squares problem (TBB-parallel).
StatusOr<LaplaceOperator> FitDdlAsymmetric(const MeshTopology& topology,
                                           const OperatorSource& source,
                                           const OperatorOptions& options = {});

using OperatorFactory = StatusOr<LaplaceOperator> (*)(const MeshTopology&, const OperatorSource&,
                                                      const OperatorOptions&);

// One row of the registry table.
struct OperatorInfo {
  std::string_view name;              // stable, lower case: "cotan-area"
  std::optional<OperatorId> wire_id;  // set for operators a decoder can rebuild (kVertex only)
  std::string_view description;
  bool needs_geometry = false;      // uses OperatorSource::reference_frame
  bool needs_trajectories = false;  // uses OperatorSource::trajectories
  bool symmetric = false;
  bool unit_sum = false;
  OperatorFactory factory = nullptr;
  OperatorDomain domain = OperatorDomain::kVertex;  // of every operator this row builds
};

// "vertex", "spacetime" or "element".
std::string_view OperatorDomainName(OperatorDomain domain);

// The table, in a fixed order. Adding an operator is one factory plus one row here.
std::span<const OperatorInfo> OperatorRegistry();
// Lookups; unknown → kNotFound whose message lists every name (or ID) that exists.
StatusOr<const OperatorInfo*> FindOperator(std::string_view name);
StatusOr<const OperatorInfo*> FindOperator(OperatorId id);
// Looks up `name` and builds it. Missing inputs → kInvalidArgument naming what is needed; a
// non-vertex domain without options.allow_any_domain → kUnsupported.
//
// The two rows without wire ID and their inputs:
//   spacetime  kSpacetime, from OperatorSource::trajectories read as F frames (V×3F, column
//              3k + axis: SourceFromSequence), options.spacetime. matrix = the DEC stiffness W
//              (symmetric, block tridiagonal, F·(V + 2E) + 2·V·(F − 1) nonzeros), mass = ⋆0, so
//              the paper's symmetrised Δ = M^{−1/2}·W·M^{−1/2} and unsymmetrised Δu = M⁻¹·W.
//              Needs F ≥ 2 frames.
//   bspline    kElement, from OperatorSource::reference_frame and options.bspline: matrix = the
//              element stiffness L (N×N, symmetric, L·1 = 0), mass_matrix = D, evaluation = the
//              V×N element values at the vertices.
// Both recover the triangles from the topology's edge/opposite table, so triangles beyond the
// second on a non-manifold edge are not seen.
StatusOr<LaplaceOperator> BuildOperator(std::string_view name, const MeshTopology& topology,
                                        const OperatorSource& source,
                                        const OperatorOptions& options = {});

}  // namespace dmc

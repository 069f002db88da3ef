// A discrete Laplace operator on a fixed-connectivity mesh as every dmc library holds it: the
// sparse matrix, the weights it was assembled from, and the one assembly routine (dmc_operators;
// decoder side). The formulas are in dmc/operator_formulas.h, the solvers in
// dmc/sparse_solvers.h, the fits and the registry in dmc/ddl_fit.h and dmc/operator_registry.h.
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
// Weight layouts (the order the codec transmits weights in):
//   kPerEdge          one value per undirected edge, in MeshTopology::edges order (w_ij = w_ji).
//   kPerDirectedEdge  one value per directed edge i→j, in the CSR order of the topology's rings:
//                     the weight of i→ring_neighbors[k] is values[k], k in
//                     [ring_offsets[i], ring_offsets[i+1]).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <string>
#include <vector>

#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

using SparseMatrixD = Eigen::SparseMatrix<double>;  // column-major, int storage indices

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

// Builds a LaplaceOperator from already known weights (e.g. DDL weights decoded from a stream):
// assembles the matrix and fills symmetric / unit_sum from the layout and name.
StatusOr<LaplaceOperator> OperatorFromWeights(std::string name, const MeshTopology& topology,
                                              OperatorWeights weights, bool unit_sum);

}  // namespace dmc

// Symmetric data-dependent Laplacian (thesis chapter 5): one weight per edge, rows unit sum,
// fitted so that δ = L·C is as small as possible on the given trajectories.
//
// Formulation. With unit row sums, δ_i = Σ_j w_ij (c_j − c_i), so the objective is wᵀHw with
// H = Q'ᵀQ' built from scalar products of trajectory DIFFERENCES (exactly translation invariant
// and free of the cancellation that raw products c_j·c_k suffer on data far from the origin):
//   H_ef = Σ_{i ∈ e ∩ f} (c_j − c_i)·(c_k − c_i)   for e = (i, j), f = (i, k),
// nonzero only for edges sharing a vertex. Dividing by s (mean squared edge difference) makes
// everything dimensionless: minimise wᵀMw − 2gᵀw, M = H/s + 2μ_t I, g_e = μ_t (ref_ij + ref_ji),
// subject to A·w = 1 (A: kept vertex–edge incidence), μ_t = μ + min_mu.
//
// Solver. Augmented Lagrangian with per-constraint penalties ρ·h_i (h_i the mean of M's diagonal
// around vertex i, so every constraint is penalised in its own local units):
//   K = M + ρ Σ_i h_i a_i a_iᵀ   (same sparsity as H: a_i a_iᵀ couples the edges around i),
// factored ONCE; each iteration is one solve, then λ_i += ρ h_i (a_iᵀw − 1). A final exact
// projection w −= Aᵀ(AAᵀ)⁻¹(Aw − 1) through the V×V signless Laplacian AAᵀ brings the
// constraints to rounding level even if the iteration stalls.
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <deque>

#include "dmc/operators.h"
#include "fitting/ddl_common.h"

namespace dmc {
namespace {

using fitting_internal::RingDifferences;

// Penalty of the augmented Lagrangian in units of the local diagonal: large enough for a fast
// multiplier iteration, small enough to keep K well conditioned for the Cholesky factorisation.
constexpr double kPenalty = 1e3;
constexpr int kMaxIterations = 200;
constexpr double kConstraintTolerance = 1e-12;

// Which unit-sum constraints enter A. Every non-isolated vertex has one, except one vertex per
// bipartite component, whose constraint is a linear combination of the others (see operators.h).
struct ConstraintSet {
  std::vector<int> row_of_vertex;  // constraint row, or -1 (isolated or dropped)
  int row_count = 0;
  int dropped = 0;
  int inconsistent = 0;
};

ConstraintSet ChooseConstraints(const MeshTopology& topology) {
  const int v_count = topology.vertex_count;
  std::vector<int8_t> colour(v_count, -1);
  std::vector<char> dropped(v_count, 0);
  ConstraintSet result;
  std::deque<int> queue;
  for (int start = 0; start < v_count; ++start) {
    if (colour[start] >= 0 || topology.degree(start) == 0) continue;
    bool bipartite = true;
    int colour_count[2] = {0, 0};
    int largest_vertex = start;
    colour[start] = 0;
    queue.push_back(start);
    while (!queue.empty()) {
      const int v = queue.front();
      queue.pop_front();
      ++colour_count[colour[v]];
      largest_vertex = std::max(largest_vertex, v);
      for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
        const int n = topology.ring_neighbors[k];
        if (colour[n] < 0) {
          colour[n] = static_cast<int8_t>(1 - colour[v]);
          queue.push_back(n);
        } else if (colour[n] == colour[v]) {
          bipartite = false;  // an odd cycle: this component's constraints are independent
        }
      }
    }
    if (bipartite) {
      dropped[largest_vertex] = 1;
      ++result.dropped;
      // Σ over one colour class of the constraints equals the sum over the other (both count
      // every edge once), so unit sums need equally large classes.
      if (colour_count[0] != colour_count[1]) ++result.inconsistent;
    }
  }
  result.row_of_vertex.assign(v_count, -1);
  for (int v = 0; v < v_count; ++v) {
    if (topology.degree(v) > 0 && !dropped[v]) result.row_of_vertex[v] = result.row_count++;
  }
  return result;
}

// (A·w − 1) over the kept constraints, indexed by constraint row.
Eigen::VectorXd ConstraintViolation(const MeshTopology& topology, const ConstraintSet& constraints,
                                    const Eigen::VectorXd& w) {
  Eigen::VectorXd violation(constraints.row_count);
  for (int v = 0; v < topology.vertex_count; ++v) {
    const int row = constraints.row_of_vertex[v];
    if (row < 0) continue;
    double sum = 0.0;
    for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
      sum += w[topology.ring_edges[k]];
    }
    violation[row] = sum - 1.0;
  }
  return violation;
}

// Lower triangle of K = H/s + 2μ_t I + ρ Σ_i h_i a_i a_iᵀ.
SparseMatrixD AssembleSystem(const MeshTopology& topology, const Eigen::MatrixXd& trajectories,
                             const ConstraintSet& constraints, double scale, double mu_total,
                             const std::vector<double>& local_scale) {
  const int v_count = topology.vertex_count, e_count = topology.edge_count();
  // Each vertex of degree d writes the d(d+1)/2 lower-triangle entries of its local block into
  // its own slice of the triplet array, so the parallel fill is deterministic.
  std::vector<size_t> offset(v_count + 1, 0);
  for (int v = 0; v < v_count; ++v) {
    const size_t d = static_cast<size_t>(topology.degree(v));
    offset[v + 1] = offset[v] + d * (d + 1) / 2;
  }
  std::vector<Eigen::Triplet<double>> triplets(offset[v_count] + static_cast<size_t>(e_count));
  tbb::parallel_for(
      tbb::blocked_range<int>(0, v_count, 256), [&](const tbb::blocked_range<int>& r) {
        Eigen::MatrixXd differences, gram;
        for (int v = r.begin(); v < r.end(); ++v) {
          const int degree = topology.degree(v);
          if (degree == 0) continue;
          RingDifferences(topology, trajectories, v, differences);
          gram.noalias() = differences * differences.transpose();
          const double penalty =
              constraints.row_of_vertex[v] >= 0 ? kPenalty * local_scale[v] : 0.0;
          const int* edges = topology.ring_edges.data() + topology.ring_offsets[v];
          size_t slot = offset[v];
          for (int a = 0; a < degree; ++a) {
            for (int b = 0; b <= a; ++b) {
              const int row = std::max(edges[a], edges[b]), col = std::min(edges[a], edges[b]);
              triplets[slot++] = {row, col, gram(a, b) / scale + penalty};
            }
          }
        }
      });
  for (int e = 0; e < e_count; ++e) triplets[offset[v_count] + e] = {e, e, 2.0 * mu_total};
  SparseMatrixD system(e_count, e_count);
  system.setFromTriplets(triplets.begin(), triplets.end());
  return system;
}

// AAᵀ over the kept constraints: deg(v) on the diagonal, 1 between adjacent kept vertices.
SparseMatrixD SignlessLaplacian(const MeshTopology& topology, const ConstraintSet& constraints) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(topology.ring_neighbors.size() + topology.vertex_count);
  for (int v = 0; v < topology.vertex_count; ++v) {
    const int row = constraints.row_of_vertex[v];
    if (row < 0) continue;
    triplets.emplace_back(row, row, topology.degree(v));
    for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
      const int col = constraints.row_of_vertex[topology.ring_neighbors[k]];
      if (col >= 0 && col < row) triplets.emplace_back(row, col, 1.0);
    }
  }
  SparseMatrixD matrix(constraints.row_count, constraints.row_count);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  return matrix;
}

// The fit's per-edge terms: the diagonal of M (both endpoints see ‖c_j − c_i‖²) plus 2μ_t, and
// the linear term μ_t (r_ij + r_ji) pulling toward the reference weights.
struct EdgeTerms {
  Eigen::VectorXd diagonal, linear;
};

EdgeTerms ComputeEdgeTerms(const MeshTopology& topology, const Eigen::MatrixXd& trajectories,
                           const std::vector<double>& reference, double scale, double mu_total) {
  const int e_count = topology.edge_count();
  EdgeTerms terms{Eigen::VectorXd(e_count), Eigen::VectorXd(e_count)};
  for (int e = 0; e < e_count; ++e) {
    const int i = topology.edges[e][0], j = topology.edges[e][1];
    terms.diagonal[e] =
        2.0 * (trajectories.row(j) - trajectories.row(i)).squaredNorm() / scale + 2.0 * mu_total;
    terms.linear[e] =
        mu_total * (reference[RingSlot(topology, i, j)] + reference[RingSlot(topology, j, i)]);
  }
  return terms;
}

// The mean of the edge diagonal around each vertex: the scale of its constraint's penalty.
std::vector<double> LocalPenaltyScales(const MeshTopology& topology,
                                       const Eigen::VectorXd& edge_diagonal) {
  std::vector<double> local_scale(topology.vertex_count, 0.0);
  for (int v = 0; v < topology.vertex_count; ++v) {
    const int degree = topology.degree(v);
    if (degree == 0) continue;
    double sum = 0.0;
    for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
      sum += edge_diagonal[topology.ring_edges[k]];
    }
    // Floor: a vertex whose edges all have zero length in trajectory space still needs a
    // penalty for its constraint to bind.
    local_scale[v] = std::max(sum / degree, 1e-12);
  }
  return local_scale;
}

StatusOr<SparseSpdSolver> FactorFitSystem(const SparseMatrixD& system, int e_count,
                                          const SolverOptions& requested) {
  SolverOptions solver_options = requested;
  // The multiplier iteration and the final projection absorb a loose inner solve, and a system
  // determined only by min_mu is legitimately ill-conditioned: require definiteness only.
  solver_options.min_pivot_ratio = 0.0;
  solver_options.max_relative_residual = 1e-4;
  // On the edge graph METIS's analysis costs more than its fill saves until ~150k edges.
  if (solver_options.ordering == SolverOrdering::kAuto) {
    solver_options.ordering = e_count < 150000 ? SolverOrdering::kAmd : SolverOrdering::kMetis;
  }
  StatusOr<SparseSpdSolver> factored = SparseSpdSolver::Factor(system, solver_options);
  if (!factored.ok()) {
    // K is definite in exact arithmetic (2μ_t > 0); failing here means the data leave weights so
    // undetermined that min_mu is lost in rounding.
    return factored.status().WithContext("ddl: fit system (raise mu or min_mu)");
  }
  return factored;
}

// The augmented-Lagrangian iteration on the unit-sum constraints: solve for w, then move the
// multipliers along the violation, until it is below kConstraintTolerance or kMaxIterations.
StatusOr<Eigen::VectorXd> SolveWithMultipliers(
    const MeshTopology& topology, const ConstraintSet& constraints, const SparseSpdSolver& solver,
    const Eigen::VectorXd& linear, const std::vector<double>& local_scale, OperatorStats& stats) {
  const int e_count = topology.edge_count();
  Eigen::VectorXd multipliers = Eigen::VectorXd::Zero(constraints.row_count);
  Eigen::VectorXd w(e_count);
  Eigen::MatrixXd rhs(e_count, 1);
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    for (int e = 0; e < e_count; ++e) {
      double value = linear[e];
      for (const int v : topology.edges[e]) {
        const int row = constraints.row_of_vertex[v];
        if (row >= 0) value += kPenalty * local_scale[v] - multipliers[row];
      }
      rhs(e, 0) = value;
    }
    DMC_ASSIGN_OR_RETURN(Eigen::MatrixXd solution, solver.Solve(rhs));
    w = solution.col(0);
    const Eigen::VectorXd violation = ConstraintViolation(topology, constraints, w);
    ++stats.solver_iterations;
    for (int v = 0; v < topology.vertex_count; ++v) {
      const int row = constraints.row_of_vertex[v];
      if (row >= 0) multipliers[row] += kPenalty * local_scale[v] * violation[row];
    }
    if (violation.size() == 0 || violation.cwiseAbs().maxCoeff() < kConstraintTolerance) break;
  }
  return w;
}

// Exact projection of w onto A·w = 1 (minimum-norm correction); records the remaining error.
Status ProjectOntoConstraints(const MeshTopology& topology, const ConstraintSet& constraints,
                              SolverBackend backend, Eigen::VectorXd& w, OperatorStats& stats) {
  if (constraints.row_count == 0) return Status::Ok();
  DMC_ASSIGN_OR_RETURN(
      SparseSpdSolver projector,
      SparseSpdSolver::Factor(SignlessLaplacian(topology, constraints), SolverOptions{backend}));
  DMC_ASSIGN_OR_RETURN(Eigen::MatrixXd correction,
                       projector.Solve(ConstraintViolation(topology, constraints, w)));
  for (int e = 0; e < topology.edge_count(); ++e) {
    for (const int v : topology.edges[e]) {
      const int row = constraints.row_of_vertex[v];
      if (row >= 0) w[e] -= correction(row, 0);
    }
  }
  stats.constraint_error = ConstraintViolation(topology, constraints, w).cwiseAbs().maxCoeff();
  return Status::Ok();
}

}  // namespace

StatusOr<LaplaceOperator> FitDdlSymmetric(const MeshTopology& topology,
                                          const OperatorSource& source,
                                          const OperatorOptions& options) {
  DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd* trajectories_ptr,
                       fitting_internal::RequireTrajectories(topology, source, "ddl"));
  const Eigen::MatrixXd& trajectories = *trajectories_ptr;
  if (!(options.ddl.mu >= 0.0) || !(options.ddl.min_mu >= 0.0) || !std::isfinite(options.ddl.mu) ||
      !std::isfinite(options.ddl.min_mu)) {
    return InvalidArgumentError(
        fmt::format("ddl: mu ({}) and min_mu ({}) must be finite and non-negative", options.ddl.mu,
                    options.ddl.min_mu));
  }
  DMC_ASSIGN_OR_RETURN(std::vector<double> reference,
                       fitting_internal::ReferenceDirectedWeights(topology, source, options));
  const int e_count = topology.edge_count();
  const double mu_total = options.ddl.mu + options.ddl.min_mu;
  const double scale = fitting_internal::MeanSquaredEdgeDifference(topology, trajectories);
  const ConstraintSet constraints = ChooseConstraints(topology);

  OperatorStats stats;
  stats.dropped_constraints = constraints.dropped;
  stats.inconsistent_rows = constraints.inconsistent;
  stats.isolated_vertices = topology.isolated_vertex_count;
  if (e_count == 0) {
    return OperatorFromWeights("ddl", topology, {WeightLayout::kPerEdge, {}}, true);
  }
  const EdgeTerms terms = ComputeEdgeTerms(topology, trajectories, reference, scale, mu_total);
  const std::vector<double> local_scale = LocalPenaltyScales(topology, terms.diagonal);
  DMC_ASSIGN_OR_RETURN(const SparseSpdSolver solver,
                       FactorFitSystem(AssembleSystem(topology, trajectories, constraints, scale,
                                                      mu_total, local_scale),
                                       e_count, options.solver));
  DMC_ASSIGN_OR_RETURN(Eigen::VectorXd w, SolveWithMultipliers(topology, constraints, solver,
                                                               terms.linear, local_scale, stats));
  DMC_RETURN_IF_ERROR(
      ProjectOntoConstraints(topology, constraints, options.solver.backend, w, stats));
  DMC_ASSIGN_OR_RETURN(LaplaceOperator result,
                       OperatorFromWeights("ddl", topology,
                                           {WeightLayout::kPerEdge,
                                            std::vector<double>(w.data(), w.data() + e_count)},
                                           constraints.inconsistent == 0));
  stats.fit_residual = fitting_internal::DeltaEnergy(result.matrix, trajectories);
  result.stats = stats;
  return result;
}

}  // namespace dmc

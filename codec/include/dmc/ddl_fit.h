// Data-dependent Laplacians (DDL): weights fitted to the trajectories they will code (dmc_fitting;
// encoder and processing side only, the decoder never links them).
#pragma once

#include "dmc/laplace_operator.h"
#include "dmc/operator_options.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

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

}  // namespace dmc

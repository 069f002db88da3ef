// Pieces shared by the symmetric and asymmetric DDL fits.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "dmc/operators.h"

namespace dmc::fitting_internal {

// Checks that the source holds finite V×r trajectories (r ≥ 1) and returns them.
StatusOr<const Eigen::MatrixXd*> RequireTrajectories(const MeshTopology& topology,
                                                     const OperatorSource& source,
                                                     std::string_view operator_name);

// Directed reference weights of the Tikhonov term (Tutte, or unit-sum cotangent from the
// source's reference frame).
StatusOr<std::vector<double>> ReferenceDirectedWeights(const MeshTopology& topology,
                                                       const OperatorSource& source,
                                                       const OperatorOptions& options);

// s: the mean over directed edges of ‖c_j − c_i‖² (equivalently over undirected edges), the unit
// the regulariser is measured in. 1 when every edge has zero length in trajectory space.
double MeanSquaredEdgeDifference(const MeshTopology& topology, const Eigen::MatrixXd& trajectories);

// Σ_i ‖Σ_j w_ij (c_j − c_i)‖² for an operator matrix (any layout).
double DeltaEnergy(const SparseMatrixD& laplacian, const Eigen::MatrixXd& trajectories);

// Fills D (deg×r) with the rows c_j − c_i of vertex i's ring, in ring order.
inline void RingDifferences(const MeshTopology& topology, const Eigen::MatrixXd& trajectories,
                            int i, Eigen::MatrixXd& differences) {
  const int begin = topology.ring_offsets[i], degree = topology.degree(i);
  differences.resize(degree, trajectories.cols());
  for (int a = 0; a < degree; ++a) {
    differences.row(a) = trajectories.row(topology.ring_neighbors[begin + a]) - trajectories.row(i);
  }
}

}  // namespace dmc::fitting_internal

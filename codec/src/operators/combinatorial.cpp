// Operators from connectivity alone: Kirchhoff (graph Laplacian) and Tutte (its unit-sum rows).
#include "dmc/operator_formulas.h"

namespace dmc {

StatusOr<LaplaceOperator> BuildKirchhoff(const MeshTopology& topology) {
  // w_ij = 1: L = A − D, the negative of the thesis's D − A (our diagonal is −deg(i)).
  return OperatorFromWeights(
      "kirchhoff", topology,
      {WeightLayout::kPerEdge, std::vector<double>(topology.edges.size(), 1.0)}, false);
}

StatusOr<LaplaceOperator> BuildTutte(const MeshTopology& topology) {
  return OperatorFromWeights(
      "tutte", topology, {WeightLayout::kPerDirectedEdge, TutteDirectedWeights(topology)}, true);
}

}  // namespace dmc

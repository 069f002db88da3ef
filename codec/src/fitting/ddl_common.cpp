#include "fitting/ddl_common.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <functional>

namespace dmc::fitting_internal {

StatusOr<const Eigen::MatrixXd*> RequireTrajectories(const MeshTopology& topology,
                                                     const OperatorSource& source,
                                                     std::string_view operator_name) {
  if (!source.trajectories.has_value()) {
    return InvalidArgumentError(fmt::format(
        "operator {} is fitted to trajectories: give a sequence, a frame or V×r coefficients",
        operator_name));
  }
  const Eigen::MatrixXd& trajectories = *source.trajectories;
  if (trajectories.rows() != topology.vertex_count || trajectories.cols() < 1) {
    return MismatchError(
        fmt::format("operator {}: trajectories are {}×{}, the mesh has {} vertices", operator_name,
                    trajectories.rows(), trajectories.cols(), topology.vertex_count));
  }
  if (!trajectories.allFinite()) {
    return InvalidArgumentError(
        fmt::format("operator {}: trajectories are not finite", operator_name));
  }
  return &trajectories;
}

StatusOr<std::vector<double>> ReferenceDirectedWeights(const MeshTopology& topology,
                                                       const OperatorSource& source,
                                                       const OperatorOptions& options) {
  switch (options.ddl.reference) {
    case DdlReference::kTutte:
      return TutteDirectedWeights(topology);
    case DdlReference::kCotan: {
      if (!source.reference_frame.has_value()) {
        return InvalidArgumentError(
            "a cotangent DDL reference needs a reference frame (positions) in the source");
      }
      DMC_ASSIGN_OR_RETURN(LaplaceOperator cotan,
                           BuildCotan(topology, *source.reference_frame, options.geometric));
      return std::move(cotan.weights.values);
    }
  }
  return InternalError("unknown DDL reference");
}

double MeanSquaredEdgeDifference(const MeshTopology& topology,
                                 const Eigen::MatrixXd& trajectories) {
  const int e_count = topology.edge_count();
  if (e_count == 0) return 1.0;
  // Fixed-grain deterministic reduction: the same partition on every run.
  const double sum = tbb::parallel_deterministic_reduce(
      tbb::blocked_range<int>(0, e_count, 1024), 0.0,
      [&](const tbb::blocked_range<int>& range, double partial) {
        for (int e = range.begin(); e < range.end(); ++e) {
          partial +=
              (trajectories.row(topology.edges[e][1]) - trajectories.row(topology.edges[e][0]))
                  .squaredNorm();
        }
        return partial;
      },
      std::plus<double>());
  const double mean = sum / e_count;
  return mean > 0.0 ? mean : 1.0;
}

double DeltaEnergy(const SparseMatrixD& laplacian, const Eigen::MatrixXd& trajectories) {
  return (laplacian * trajectories).squaredNorm();
}

}  // namespace dmc::fitting_internal

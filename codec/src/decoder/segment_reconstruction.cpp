#include "decoder/segment_reconstruction.h"

#include <cmath>
#include <string>

#include "bitstream/syntax.h"

namespace dmc {

StatusOr<LaplaceOperator> RebuildSegmentOperator(const MeshTopology& topology,
                                                 const SegmentSyntax& syntax) {
  const auto id = static_cast<OperatorId>(syntax.header.operator_id);
  if (id == OperatorId::kDdl) {
    OperatorWeights weights;
    weights.layout = WeightLayout::kPerEdge;
    weights.values.resize(syntax.edge_weights.size());
    const double unit = std::ldexp(1.0, -syntax.header.weight_bits);
    for (size_t e = 0; e < syntax.edge_weights.size(); ++e) {
      weights.values[e] = static_cast<double>(syntax.edge_weights[e]) * unit;
    }
    return RebuildOperator(id, topology, nullptr, &weights);
  }
  if (format::IsGeometricOperator(syntax.header.operator_id)) {
    return RebuildOperator(id, topology, &syntax.reference_frame, nullptr);
  }
  if (id == OperatorId::kKirchhoff || id == OperatorId::kTutte) {
    return RebuildOperator(id, topology, nullptr, nullptr);
  }
  return UnsupportedError("operator wire ID " + std::to_string(syntax.header.operator_id) +
                          " is not a codec operator of this version");
}

StatusOr<Eigen::MatrixXd> ReconstructCoefficients(const MeshTopology& topology,
                                                  const LaplaceOperator& laplace,
                                                  const SegmentSyntax& syntax) {
  DMC_ASSIGN_OR_RETURN(auto solver,
                       AnchoredLaplacianSolver::Create(topology, laplace.matrix, syntax.anchors,
                                                       syntax.header.anchor_weight));
  return solver.Solve(syntax.delta, syntax.anchor_values);
}

void SynthesizeFrames(const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis,
                      const Eigen::MatrixXd& coefficients, int frame_count, float* frames) {
  const Eigen::Index v_count = coefficients.rows();
  // trajectories(v, 3f + axis): one GEMM, then the mean trajectory added per column.
  Eigen::MatrixXd trajectories(v_count, 3 * frame_count);
  if (basis.cols() > 0) {
    trajectories.noalias() = coefficients * basis.transpose();
  } else {
    trajectories.setZero();
  }
  trajectories.rowwise() += mean.transpose();
  for (int f = 0; f < frame_count; ++f) {
    float* frame = frames + static_cast<size_t>(f) * v_count * 3;
    for (Eigen::Index v = 0; v < v_count; ++v) {
      for (int axis = 0; axis < 3; ++axis) {
        frame[v * 3 + axis] = static_cast<float>(trajectories(v, 3 * f + axis));
      }
    }
  }
}

}  // namespace dmc

#include "decoder/segment_reconstruction.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
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

SolverOrdering NormalMatrixOrdering(int vertex_count) {
  return vertex_count < kNormalMatrixNestedDissectionThreshold ? SolverOrdering::kAmd
                                                               : SolverOrdering::kMetis;
}

StatusOr<Eigen::MatrixXd> ReconstructCoefficients(const MeshTopology& topology,
                                                  const LaplaceOperator& laplace,
                                                  const SegmentSyntax& syntax) {
  SolverOptions options;
  options.ordering = NormalMatrixOrdering(topology.vertex_count);
  DMC_ASSIGN_OR_RETURN(auto solver,
                       AnchoredLaplacianSolver::Create(topology, laplace.matrix, syntax.anchors,
                                                       syntax.header.anchor_weight, options));
  return solver.Solve(syntax.delta, syntax.anchor_values);
}

Status SynthesizeFrames(const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis,
                        const Eigen::MatrixXd& coefficients, int frame_count, float* frames) {
  const Eigen::Index v_count = coefficients.rows();
  const Eigen::Index width = 3 * static_cast<Eigen::Index>(frame_count);
  // Fixed-size vertex blocks: each block's trajectories are one small GEMM, so the decoder never
  // holds the V×3F binary64 matrix (twice the float32 output), and the partition — hence every
  // rounding — is the same for any thread count.
  constexpr Eigen::Index kBlockRows = 256;
  const Eigen::Index block_count = (v_count + kBlockRows - 1) / kBlockRows;
  std::atomic<Eigen::Index> first_bad_vertex{v_count};
  // One block buffer per worker thread (256 × 3F doubles, 1 MB at 175 frames), not one
  // allocation (and its page faults) per block.
  tbb::enumerable_thread_specific<Eigen::MatrixXd> buffers;
  tbb::parallel_for(Eigen::Index{0}, block_count, [&](Eigen::Index block) {
    const Eigen::Index begin = block * kBlockRows;
    const Eigen::Index rows = std::min(kBlockRows, v_count - begin);
    Eigen::MatrixXd& trajectories = buffers.local();
    trajectories.resize(rows, width);
    if (basis.cols() > 0) {
      trajectories.noalias() = coefficients.middleRows(begin, rows) * basis.transpose();
    } else {
      trajectories.setZero();
    }
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    bool in_range = true;
    // The mean is added while converting (the same double sum as a separate pass, one pass less
    // over the block).
    for (int f = 0; f < frame_count; ++f) {
      float* frame = frames + (static_cast<size_t>(f) * v_count + begin) * 3;
      for (int axis = 0; axis < 3; ++axis) {
        const double offset = mean[3 * f + axis];
        const double* column = trajectories.col(3 * f + axis).data();
        for (Eigen::Index v = 0; v < rows; ++v) {
          const double x = column[v] + offset;
          // NaN fails the comparison; values that round to ±FLT_MAX are still representable.
          in_range = in_range && std::abs(x) <= kFloatMax;
          frame[v * 3 + axis] = static_cast<float>(x);
        }
      }
    }
    if (!in_range) {
      Eigen::Index expected = first_bad_vertex.load();
      while (begin < expected && !first_bad_vertex.compare_exchange_weak(expected, begin)) {
      }
    }
  });
  if (first_bad_vertex.load() < v_count) {
    return CorruptStreamError("reconstructed positions near vertex " +
                              std::to_string(first_bad_vertex.load()) +
                              " are not finite or exceed the float32 range");
  }
  return Status::Ok();
}

}  // namespace dmc

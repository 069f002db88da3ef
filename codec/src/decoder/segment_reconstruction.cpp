#include "decoder/segment_reconstruction.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "decoder/synthesis_kernel.h"
#include "dmc/operator_traits.h"

namespace dmc {

StatusOr<LaplaceOperator> RebuildSegmentOperator(const MeshTopology& topology,
                                                 const SegmentSyntax& syntax) {
  const auto id = static_cast<OperatorId>(syntax.header.operator_id);
  const OperatorTraits* traits = FindOperatorTraits(id);
  switch (traits != nullptr ? traits->side_info : OperatorSideInfo::kNotCarried) {
    case OperatorSideInfo::kEdgeWeights: {
      OperatorWeights weights;
      weights.layout = WeightLayout::kPerEdge;
      weights.values.resize(syntax.edge_weights.size());
      const double unit = std::ldexp(1.0, -syntax.header.weight_bits);
      for (size_t e = 0; e < syntax.edge_weights.size(); ++e) {
        weights.values[e] = static_cast<double>(syntax.edge_weights[e]) * unit;
      }
      return RebuildOperator(id, topology, nullptr, &weights);
    }
    case OperatorSideInfo::kReferenceFrame:
      return RebuildOperator(id, topology, &syntax.reference_frame, nullptr);
    case OperatorSideInfo::kNone:
      return RebuildOperator(id, topology, nullptr, nullptr);
    case OperatorSideInfo::kNotCarried:
      break;
  }
  return UnsupportedError("operator wire ID " + std::to_string(syntax.header.operator_id) +
                          " is not a codec operator of this version");
}

SolverOrdering NormalMatrixOrdering(int vertex_count) {
  return vertex_count < kNormalMatrixNestedDissectionThreshold ? SolverOrdering::kAmd
                                                               : SolverOrdering::kMetis;
}

StatusOr<AnchoredLaplacianSolver> FactorSegmentOperator(const MeshTopology& topology,
                                                        const LaplaceOperator& laplace,
                                                        const SegmentSyntax& syntax,
                                                        uint64_t max_matrix_bytes) {
  SolverOptions options;
  options.max_matrix_bytes = max_matrix_bytes;
  options.ordering = NormalMatrixOrdering(topology.vertex_count);
  options.residual_check_spacing = kNormalMatrixResidualCheckSpacing;
  return AnchoredLaplacianSolver::Create(topology, laplace.matrix, syntax.anchors,
                                         syntax.header.anchor_weight, options);
}

Status SynthesizeFrames(const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis,
                        const Eigen::MatrixXd& coefficients, int frame_count, float* frames) {
  const Eigen::Index v_count = coefficients.rows();
  const Eigen::Index width = 3 * static_cast<Eigen::Index>(frame_count);
  // Fixed-size vertex blocks, in parallel, the vertices of a block four at a time: the decoder
  // never holds the V×3F binary64 matrix (twice the float32 output), and each position is one
  // sequential sum over k (SumTrajectoryProducts), so no partition or thread count changes a bit.
  constexpr Eigen::Index kBlockRows = 256;
  const Eigen::Index block_count = (v_count + kBlockRows - 1) / kBlockRows;
  const int rank = static_cast<int>(basis.cols());
  // The basis with each column padded to a whole number of the widest vectors, zeros after the
  // width: the kernel then has no scalar tail (the padding's sums are never read).
  const Eigen::Index stride =
      (width + kSynthesisStrideMultiple - 1) / kSynthesisStrideMultiple * kSynthesisStrideMultiple;
  std::vector<double> padded_basis(static_cast<size_t>(stride) * rank, 0.0);
  for (int k = 0; k < rank; ++k) {
    std::copy_n(basis.col(k).data(), width, padded_basis.data() + static_cast<size_t>(k) * stride);
  }
  std::atomic<Eigen::Index> first_bad_vertex{v_count};
  struct Scratch {
    std::vector<double> sums;          // kSynthesisVertexGroup × stride
    std::vector<double> coefficients;  // the group's coefficient rows, kSynthesisVertexGroup × r
  };
  core_internal::PerThread<Scratch> scratches;
  core_internal::ParallelFor(Eigen::Index{0}, block_count, [&](Eigen::Index block) {
    const Eigen::Index begin = block * kBlockRows;
    const Eigen::Index end = std::min(v_count, begin + kBlockRows);
    Scratch& scratch = scratches.local();
    scratch.sums.resize(static_cast<size_t>(kSynthesisVertexGroup * stride));
    scratch.coefficients.resize(static_cast<size_t>(kSynthesisVertexGroup) * rank);
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    bool in_range = true;
    for (Eigen::Index group = begin; group < end; group += kSynthesisVertexGroup) {
      const int group_size =
          static_cast<int>(std::min<Eigen::Index>(kSynthesisVertexGroup, end - group));
      const double* rows[kSynthesisVertexGroup] = {};
      for (int i = 0; i < group_size; ++i) {
        double* row = scratch.coefficients.data() + static_cast<size_t>(i) * rank;
        for (int k = 0; k < rank; ++k) row[k] = coefficients(group + i, k);
        rows[i] = row;
      }
      if (rank > 0) {
        SumTrajectoryProducts(rows, group_size, padded_basis.data(), rank, stride,
                              scratch.sums.data());
      } else {
        std::fill(scratch.sums.begin(), scratch.sums.end(), 0.0);
      }
      // The mean is added while converting (the same double sum as a separate pass); frame by
      // frame, so the group's positions in a frame are written side by side.
      float* group_positions = frames + static_cast<size_t>(group) * 3;
      for (Eigen::Index j = 0; j < width; j += 3) {
        float* out = group_positions + static_cast<size_t>(j / 3) * v_count * 3;
        for (int i = 0; i < group_size; ++i) {
          const double* sums = scratch.sums.data() + static_cast<size_t>(i) * stride + j;
          for (int axis = 0; axis < 3; ++axis) {
            const double x = sums[axis] + mean[j + axis];
            // NaN fails the comparison; values that round to ±FLT_MAX are still representable.
            in_range = in_range && std::abs(x) <= kFloatMax;
            out[3 * i + axis] = static_cast<float>(x);
          }
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

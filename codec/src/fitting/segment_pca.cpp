#include "fitting/segment_pca.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <vector>

namespace dmc {

namespace {

// Row blocks of a fixed size: per-block partial results combined in block order are the same
// for any thread count.
constexpr Eigen::Index kRowBlock = 4096;

Eigen::Index RowBlocks(Eigen::Index rows) { return (rows + kRowBlock - 1) / kRowBlock; }

// Within a block, the centred double copy is made kCentredRows rows at a time: a whole block's
// (4096 × 3F × 8 bytes, 17 MB at 175 frames, one per thread) would be the encoder's largest
// buffer after the trajectories themselves.
constexpr Eigen::Index kCentredRows = 256;

// Calls use(offset, centred) for consecutive runs of at most kCentredRows rows of
// trajectories[start, start + count), centred (rows minus `mean`) in double, in row order.
template <typename Matrix, typename Use>
void ForEachCentredRun(const Matrix& trajectories, const Eigen::VectorXd& mean, Eigen::Index start,
                       Eigen::Index count, Use use) {
  Eigen::MatrixXd centred;
  for (Eigen::Index offset = 0; offset < count; offset += kCentredRows) {
    const Eigen::Index n = std::min(kCentredRows, count - offset);
    centred = trajectories.middleRows(start + offset, n).template cast<double>().rowwise() -
              mean.transpose();
    use(start + offset, centred);
  }
}

// Shared by the float (encoder) and double (ComputeTrajectoryPca) trajectories: with float input
// every row is cast to double before any arithmetic, so both run the same double sums.
template <typename Matrix>
Eigen::VectorXd MeanOf(const Matrix& trajectories) {
  const Eigen::Index rows = trajectories.rows(), cols = trajectories.cols();
  const Eigen::Index blocks = RowBlocks(rows);
  std::vector<Eigen::VectorXd> partial_sums(blocks);
  tbb::parallel_for(Eigen::Index{0}, blocks, [&](Eigen::Index b) {
    const Eigen::Index start = b * kRowBlock, count = std::min(kRowBlock, rows - start);
    partial_sums[b] =
        trajectories.middleRows(start, count).template cast<double>().colwise().sum().transpose();
  });
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(cols);
  for (const auto& p : partial_sums) mean += p;
  if (rows > 0) mean /= static_cast<double>(rows);
  return mean;
}

template <typename Matrix>
SegmentPca PcaOf(const Matrix& trajectories) {
  SegmentPca pca;
  const Eigen::Index rows = trajectories.rows(), cols = trajectories.cols();
  const Eigen::Index blocks = RowBlocks(rows);
  pca.mean = MeanOf(trajectories);

  // The blocks' partial Gram matrices are computed a batch at a time (as many as run at once)
  // and added in block order as each batch ends: the same sums in the same order as holding all
  // of them, without one 3F × 3F matrix per block alive at once (25 of them at 100k vertices,
  // 4.7 MB each at 256 frames).
  const Eigen::Index batch = std::max<Eigen::Index>(2, tbb::this_task_arena::max_concurrency());
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(cols, cols);
  std::vector<Eigen::MatrixXd> partial;
  for (Eigen::Index first = 0; first < blocks; first += batch) {
    partial.resize(static_cast<size_t>(std::min(batch, blocks - first)));
    tbb::parallel_for(size_t{0}, partial.size(), [&](size_t i) {
      const Eigen::Index start = (first + static_cast<Eigen::Index>(i)) * kRowBlock;
      const Eigen::Index count = std::min(kRowBlock, rows - start);
      partial[i] = Eigen::MatrixXd::Zero(cols, cols);
      ForEachCentredRun(
          trajectories, pca.mean, start, count, [&](Eigen::Index, const Eigen::MatrixXd& centred) {
            partial[i].selfadjointView<Eigen::Lower>().rankUpdate(centred.transpose());
          });
    });
    for (const auto& p : partial) gram += p;
  }
  partial = {};
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(gram.selfadjointView<Eigen::Lower>());
  // Eigen returns ascending eigenvalues: reverse to descending.
  pca.eigenvalues = solver.eigenvalues().reverse().cwiseMax(0.0);
  pca.eigenvectors = solver.eigenvectors().rowwise().reverse();
  return pca;
}

template <typename Matrix>
Eigen::MatrixXd ProjectionOf(const Matrix& trajectories, const Eigen::VectorXd& mean,
                             const Eigen::MatrixXd& basis) {
  const Eigen::Index rows = trajectories.rows();
  Eigen::MatrixXd projected(rows, basis.cols());
  tbb::parallel_for(Eigen::Index{0}, RowBlocks(rows), [&](Eigen::Index b) {
    const Eigen::Index start = b * kRowBlock, count = std::min(kRowBlock, rows - start);
    ForEachCentredRun(trajectories, mean, start, count,
                      [&](Eigen::Index first, const Eigen::MatrixXd& centred) {
                        projected.middleRows(first, centred.rows()).noalias() = centred * basis;
                      });
  });
  return projected;
}

}  // namespace

void StoreFrame(const float* positions, int frame_in_segment, const std::vector<int32_t>& relabel,
                SegmentTrajectories& trajectories) {
  const Eigen::Index v_count = trajectories.rows();
  const Eigen::Map<const FramePositions> frame(positions, v_count, 3);
  if (relabel.empty()) {
    trajectories.middleCols(3 * frame_in_segment, 3) = frame;
  } else {
    for (Eigen::Index v = 0; v < v_count; ++v) {
      trajectories.block(v, 3 * frame_in_segment, 1, 3) = frame.row(relabel[v]);
    }
  }
}

SegmentTrajectories GatherTrajectories(const MeshSequence& sequence, int first_frame,
                                       int frame_count, const std::vector<int32_t>& relabel) {
  SegmentTrajectories x(sequence.vertex_count(), 3 * frame_count);
  for (int f = 0; f < frame_count; ++f) {
    StoreFrame(sequence.frame(first_frame + f).data(), f, relabel, x);
  }
  return x;
}

SegmentPca ComputeSegmentPca(const SegmentTrajectories& trajectories) {
  return PcaOf(trajectories);
}
SegmentPca ComputeSegmentPca(const Eigen::MatrixXd& trajectories) { return PcaOf(trajectories); }

Eigen::VectorXd MeanTrajectory(const Eigen::MatrixXd& trajectories) { return MeanOf(trajectories); }

Eigen::MatrixXd ProjectTrajectories(const SegmentTrajectories& trajectories,
                                    const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis) {
  return ProjectionOf(trajectories, mean, basis);
}
Eigen::MatrixXd ProjectTrajectories(const Eigen::MatrixXd& trajectories,
                                    const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis) {
  return ProjectionOf(trajectories, mean, basis);
}

Eigen::MatrixXd MeanShape(const SegmentTrajectories& trajectories) {
  const Eigen::Index frames = trajectories.cols() / 3;
  Eigen::MatrixXd shape = Eigen::MatrixXd::Zero(trajectories.rows(), 3);
  for (Eigen::Index f = 0; f < frames; ++f) {
    shape += trajectories.middleCols(3 * f, 3).cast<double>();
  }
  if (frames > 0) shape /= static_cast<double>(frames);
  return shape;
}

}  // namespace dmc

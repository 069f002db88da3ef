#include "encoder/segment_pca.h"

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <vector>

namespace dmc {

Eigen::MatrixXd TrajectoryMatrix(const MeshSequence& sequence, int first_frame, int frame_count,
                                 const std::vector<int32_t>& relabel) {
  const int v_count = sequence.vertex_count();
  Eigen::MatrixXd x(v_count, 3 * frame_count);
  for (int f = 0; f < frame_count; ++f) {
    const auto frame = sequence.frame(first_frame + f);
    if (relabel.empty()) {
      x.middleCols(3 * f, 3) = frame.cast<double>();
    } else {
      for (int v = 0; v < v_count; ++v)
        x.block(v, 3 * f, 1, 3) = frame.row(relabel[v]).cast<double>();
    }
  }
  return x;
}

SegmentPca ComputeSegmentPca(const Eigen::MatrixXd& trajectories) {
  SegmentPca pca;
  const Eigen::Index rows = trajectories.rows(), cols = trajectories.cols();
  pca.mean = trajectories.colwise().mean().transpose();
  // Gram matrix over fixed blocks of rows, each computed independently, then summed in block
  // order: the result does not depend on how TBB schedules the blocks.
  constexpr Eigen::Index kBlock = 4096;
  const Eigen::Index blocks = (rows + kBlock - 1) / kBlock;
  std::vector<Eigen::MatrixXd> partial(blocks);
  tbb::parallel_for(Eigen::Index{0}, blocks, [&](Eigen::Index b) {
    const Eigen::Index start = b * kBlock, count = std::min(kBlock, rows - start);
    const Eigen::MatrixXd centred =
        trajectories.middleRows(start, count).rowwise() - pca.mean.transpose();
    partial[b] = Eigen::MatrixXd::Zero(cols, cols);
    partial[b].selfadjointView<Eigen::Lower>().rankUpdate(centred.transpose());
  });
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(cols, cols);
  for (const auto& p : partial) gram += p;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(gram.selfadjointView<Eigen::Lower>());
  // Eigen returns ascending eigenvalues: reverse to descending.
  pca.eigenvalues = solver.eigenvalues().reverse().cwiseMax(0.0);
  pca.eigenvectors = solver.eigenvectors().rowwise().reverse();
  return pca;
}

}  // namespace dmc

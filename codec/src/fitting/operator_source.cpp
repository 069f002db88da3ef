// The OperatorSource constructors (dmc/operator_registry.h): what the fits and the registry's
// factories read their reference frame and trajectories from.
#include <utility>

#include "dmc/operators.h"
#include "dmc/pca.h"

namespace dmc {

OperatorSource SourceFromFrame(const FramePositionsD& positions) {
  OperatorSource source;
  source.reference_frame = positions;
  source.trajectories = Eigen::MatrixXd(positions);
  return source;
}

OperatorSource SourceFromSequence(const MeshSequence& sequence, int reference_frame_index) {
  OperatorSource source;
  source.reference_frame =
      reference_frame_index >= 0 && reference_frame_index < sequence.frame_count()
          ? sequence.frame_d(reference_frame_index)
          : MeanFrame(sequence);
  source.trajectories = TrajectoryMatrix(sequence);
  return source;
}

OperatorSource SourceFromTrajectories(Eigen::MatrixXd trajectories) {
  OperatorSource source;
  source.trajectories = std::move(trajectories);
  return source;
}

}  // namespace dmc

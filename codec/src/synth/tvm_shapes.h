// Internal: the time-varying synthetic examples (per-frame connectivity, known volume centres)
// behind SynthesizeTimeVarying(), and the pieces they share. Options are validated by the caller.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "dmc/synth.h"
#include "dmc/tvm.h"

namespace dmc::synth {

TimeVaryingSynthesis GeneratePrism(const TimeVaryingSynthOptions& options);
TimeVaryingSynthesis GenerateCollision(const TimeVaryingSynthOptions& options);

// `frame` moved rigidly by `motion`.
tvm::TvmFrame MovedFrame(const tvm::TvmFrame& frame, const Eigen::Isometry3d& motion);

// The rows of `points` moved by `motion`, as an n x 3 matrix.
FramePositionsD MovedPoints(const std::vector<Eigen::Vector3d>& points,
                            const Eigen::Isometry3d& motion);

}  // namespace dmc::synth

// Internal: the "basis" GLB layout's morph targets. A decoded dmc sequence is low rank in time (a
// segment of rank r is mean + Σ_k C_k·B_k, so each coordinate axis of its frames spans at most r +
// 1 directions), and glTF morph targets are that form exactly: base + Σ_t w_t(frame)·T_t. So
// instead of one target per frame, each block of frames (a stream segment, a clip) gets a few
// targets per axis — each moving one coordinate, so two of its three channels are zero, which
// meshopt's codec stores almost for free — and per-frame weights. The file then grows with the
// rank, not with the frame count.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace dmc::io_internal::glb {

// One morph target of a block of frames. A fitted target moves coordinate `axis` of vertex v at
// block frame j by weights[j]·values[v] (in the units of the displacements it was fitted to). A
// step target (axis −1, for a block that is not low rank) holds x, y, z per vertex: the integer
// step from the previous frame's values (the base's, for the block's first frame), with weight 1
// from its frame on and 0 before.
struct AxisTarget {
  int axis = 0;
  std::vector<int16_t> values;  // per vertex (x, y, z per vertex for a step target)
  std::vector<float> weights;   // per frame of the block
  bool steps() const { return axis < 0; }
};

// What the targets must reproduce, in the displacements' units: the root mean square and the
// largest error over every vertex and frame of the block.
struct FitTolerance {
  double rms = 0.5;
  double max = 1.0;
  int largest_value = 32767;  // of the integer targets: 32767 (int16) or 127 (int8)
};

// Targets for one axis of one block: `displacements` holds vertex v's displacement at block frame
// j in (v, j). The fewest principal directions (eigenvectors of DᵀD) whose truncation stays within
// 70 % of `tolerance`, quantised to int16 on the coarsest steps (halved until they fit) for which
// the whole fit, with weights refitted by least squares to the quantised targets, stays within
// `tolerance`. Returns no target for a block that does not move along the axis.
std::vector<AxisTarget> FitAxisTargets(const Eigen::MatrixXd& displacements, int axis,
                                       const FitTolerance& tolerance);

// Consecutive frames fitted together (a stream segment, or a clip's stretch of one).
struct FrameBlock {
  int first = 0;
  int count = 0;
};

// Splits `frame_count` written frames into blocks: a block starts at frame 0, at every frame in
// `starts`, and after `max_length` frames.
std::vector<FrameBlock> SplitBlocks(int frame_count, const std::vector<int>& starts,
                                    int max_length = 256);

// A target of one block.
struct BlockTarget {
  int block = 0;
  AxisTarget target;
};

// Writes frame j's values (x, y, z per vertex, in the fitted units) into `values`.
using FrameValues = std::function<void(int j, std::vector<double>& values)>;

// The targets of every block and axis, fitted to frame(j) − base, in block then axis order. A
// block whose axes need more fitted targets together than 1.5 × its frames (estimated from the rms
// tolerance) gets one step target per frame instead: fitted targets would cost more than steps.
// Steps put values on the integer lattice closed loop: positions (largest_value 32767) are the
// rounded frame values, within half a unit; normals (largest_value 127; frame values are 32767·n)
// follow NormalSteps.
std::vector<BlockTarget> FitBlockTargets(const FrameValues& frame, const std::vector<double>& base,
                                         std::span<const FrameBlock> blocks,
                                         const FitTolerance& tolerance);

// The compact morph layout's normal displacements from frame f−1 to frame f (unit normals, x, y,
// z per vertex), closed loop on the running sum `sum` (int8 units, starts as the base normals):
// renderers normalise n_0 + Σ w·δ, so the sum need only point along n_f, and s·n_f with the
// largest s ≤ 1 that keeps every step within int8 is taken (at least 1/16; a normal that turns
// over in one frame may then be clamped).
std::vector<int8_t> NormalSteps(const std::vector<float>& normals, std::vector<int>& sum);

// Per frame, the weight of every target (zero outside its block): the weights animation's values.
std::vector<std::vector<float>> TargetWeights(std::span<const BlockTarget> targets,
                                              std::span<const FrameBlock> blocks, int frame_count);

}  // namespace dmc::io_internal::glb

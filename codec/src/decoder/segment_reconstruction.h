// The decoder-side reconstruction of one segment from its dequantised syntax elements. The
// encoder calls exactly this code in its closed loop, so both sides rebuild identical values.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "bitstream/format.h"
#include "dmc/operators.h"
#include "dmc/status.h"
#include "dmc/topology.h"

namespace dmc {

// A segment's syntax elements after entropy decoding and dequantisation.
struct SegmentSyntax {
  format::SegmentHeader header;
  Eigen::VectorXd mean;               // 3F mean trajectory
  Eigen::MatrixXd basis;              // 3F × r dequantised basis
  FramePositionsD reference_frame;    // geometric operators: decoded reference frame (V×3)
  std::vector<int64_t> edge_weights;  // DDL: integer weights per edge (units 2^-weight_bits)
  std::vector<int32_t> anchors;       // ascending vertex indices
  std::vector<int8_t> anchor_step_exponents;  // 1.2: one per anchor (§8.5.1); before 1.2 empty
  Eigen::MatrixXd anchor_values;              // anchors × r dequantised coefficients
  Eigen::MatrixXd delta;                      // V × r dequantised delta-trajectories
};

// Rebuilds the operator the segment names (DDL from its integer weights).
StatusOr<LaplaceOperator> RebuildSegmentOperator(const MeshTopology& topology,
                                                 const SegmentSyntax& syntax);

// Fill-reducing ordering of the normal matrix LᵀL + anchors: AMD below this many vertices, nested
// dissection (METIS) from there on: below it, METIS's analysis costs more than the factorisation
// it saves; beyond, the factor's extra memory under AMD weighs more (the measurement and how to
// re-run it: tests/bench/README.md, "Normal matrices ordered by AMD"). The ordering changes only
// the last bits of the solution.
inline constexpr int kNormalMatrixNestedDissectionThreshold = 300000;
SolverOrdering NormalMatrixOrdering(int vertex_count);

// The residual check of the coefficient solves samples one column in this many (SolverOptions);
// the encoder's closed loop factors through the same function, so both sides accept alike.
inline constexpr int kNormalMatrixResidualCheckSpacing = 16;

// Factors the segment's normal matrix LᵀL + anchors (ordered by NormalMatrixOrdering): needs the
// operator, the anchors and the header, not the deltas, so a decoder can factor while the
// residuals are still being decoded. `max_matrix_bytes`: SolverOptions' (0: no bound).
StatusOr<AnchoredLaplacianSolver> FactorSegmentOperator(const MeshTopology& topology,
                                                        const LaplaceOperator& laplace,
                                                        const SegmentSyntax& syntax,
                                                        uint64_t max_matrix_bytes = 0);

// positions(v, 3f + axis) = mean(3f + axis) + Σ_k C(v, k) basis(3f + axis, k), written as float
// frames into `frames` (frame_count × V × 3, frame after frame). kCorruptStream when a position is
// not finite or exceeds the float32 range (spec §10.2); `frames` is then partly written.
Status SynthesizeFrames(const Eigen::VectorXd& mean, const Eigen::MatrixXd& basis,
                        const Eigen::MatrixXd& coefficients, int frame_count, float* frames);

}  // namespace dmc

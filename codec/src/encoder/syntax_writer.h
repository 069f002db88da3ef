// Quantisation and coding of chunk payloads (the mirror of decoder/syntax_reader.h). Each writer
// returns what the decoder will reconstruct, so the encoder continues in closed loop.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"
#include "entropy/byte_io.h"

namespace dmc::syntax {

// The bounds the decoder enforces on what an encoder writes (spec §5.3, §8), checked before the
// values are written: a stream breaking one would be rejected by every decoder, so the encoder
// refuses it with kUnsupported instead, naming the value (`what`) and `remedy`.
// The step, mean, reference frame and anchor weight bounds are format::'s (bitstream/format.h).
//
// Largest |q| of any value coded with S() (§5.3: m = |q| - 1 < 2^62).
inline constexpr int64_t kMaxSignedMagnitude = int64_t{1} << 62;

// `value` with six significant digits (%g), for the messages.
std::string ShortNumber(double value);

// kUnsupported unless 0 < step <= 2^64.
Status CheckStep(double step, std::string_view what, std::string_view remedy);
// kUnsupported unless every value / step rounds to an integer within [-limit, limit].
Status CheckQuantisedRange(const Eigen::Ref<const Eigen::MatrixXd>& values, double step,
                           int64_t limit, std::string_view what, std::string_view remedy);
// The sequence header's fields against §6.1 (the counts are checked by CheckFormatLimits).
Status CheckSequenceHeader(const format::SequenceHeader& header);
// The segment header's fields against §8.1 for a mesh of `vertex_count` vertices.
Status CheckSegmentHeader(const format::SegmentHeader& header, int vertex_count);
// The coded DDL weights (WriteDdlWeights' `decoded`) against §9.4's |W| <= 256 · 2^weight_bits.
Status CheckDdlWeights(const std::vector<int64_t>& weights, int weight_bits);

// Appends a framed chunk: u8 type, varint size, payload, u32 XXH32(payload, seed = type).
void AppendChunk(ByteWriter& out, format::ChunkType type, const std::vector<uint8_t>& payload);

std::vector<uint8_t> WriteSequenceHeader(const format::SequenceHeader& header);
std::vector<uint8_t> WriteSegmentHeader(const format::SegmentHeader& header);

// Quantises the mean trajectory with header.mean_step; returns the dequantised trajectory. The
// values must pass CheckQuantisedRange(mean, mean_step, format::kMaxMeanMagnitude).
std::vector<uint8_t> WriteMean(const Eigen::VectorXd& mean, const format::SegmentHeader& header,
                               Eigen::VectorXd* decoded);

// The basis chunk's writers: encoder/basis_writer.h.

// Quantises DDL edge weights along the shared weight schedule: explicit weights are rounded to
// units of 2^-weight_bits, the last weight of each visit is implied by the unit sum. A weight
// within `dead_zone` units of its prediction is sent as the prediction (residual 0, the cheapest
// symbol): 0.5 is plain rounding, infinity sends the predicted weights alone. Returns the
// integer weights the decoder will rebuild.
std::vector<uint8_t> WriteDdlWeights(const std::vector<double>& edge_weights,
                                     const MeshTopology& topology, int weight_bits,
                                     format::WeightPrediction prediction_mode,
                                     std::vector<int64_t>* decoded, double dead_zone = 0.5);

// Quantises a reference frame (V×3) to the grid of `step` and codes it with one-ring mean
// prediction in BreadthFirstOrder; returns the payload (f64 step + range-coded residuals) and the
// decoded frame. The frame must pass CheckQuantisedRange(frame, step,
// format::kMaxReferenceMagnitude).
std::vector<uint8_t> WriteReferenceFrame(const FramePositionsD& frame, const MeshTopology& topology,
                                         double step, FramePositionsD* decoded);

// Codes ascending anchor indices and their coefficients quantised with header.anchor_step;
// returns the dequantised anchor coefficients. The anchors' coefficients must pass
// CheckQuantisedRange(·, anchor_step, kMaxSignedMagnitude).
// In a 1.2 stream (header.version_minor ≥ 2) the anchors' step exponents (one per anchor, |e| ≤
// format::kMaxStepExponent) follow the indices; before 1.2 they must be empty.
std::vector<uint8_t> WriteAnchors(const std::vector<int32_t>& anchors,
                                  const Eigen::MatrixXd& coefficients,
                                  const format::SegmentHeader& header,
                                  Eigen::MatrixXd* decoded_values,
                                  std::span<const int8_t> step_exponents = {});

// Quantises delta-trajectories (V×r) with header.residual_step and codes them column by column
// in `vertex_order`; stores the dequantised deltas in `decoded` unless it is null (the decoder's
// values: ReadResiduals on the payload gives the same matrix). kUnsupported when a quantised
// residual would exceed format::kMaxResidualMagnitude steps (an operator that amplifies
// near-degenerate geometry enormously, with a very fine step), since no decoder would accept the
// stream. `rdo_lambda` > 0 rounds each value by rate–distortion (RdoLevel, encoder/bit_cost.h):
// the decoder is unaffected, `decoded` holds the levels chosen.
// `step_factors` (format::VertexStepFactors; empty = 1 everywhere) scale the step per vertex.
StatusOr<std::vector<uint8_t>> WriteResiduals(const Eigen::MatrixXd& delta,
                                              const MeshTopology& topology,
                                              const std::vector<int32_t>& vertex_order,
                                              const format::SegmentHeader& header,
                                              Eigen::MatrixXd* decoded, double rdo_lambda = 0.0,
                                              std::span<const double> step_factors = {});

}  // namespace dmc::syntax

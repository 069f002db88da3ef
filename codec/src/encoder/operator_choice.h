// The ddl operator's choices for one segment: which weights to code (fitted or predicted) and,
// with the fallback, which operator codes the segment at the lowest rate for its distortion.
// Every candidate is coded as the decoder will read it and measured on what the decoder rebuilds.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "decoder/segment_reconstruction.h"
#include "dmc/encoder.h"
#include "dmc/metrics.h"
#include "dmc/sequence.h"
#include "dmc/sparse_solvers.h"
#include "dmc/status.h"
#include "dmc/topology.h"
#include "dmc/wire_ids.h"
#include "fitting/segment_pca.h"

namespace dmc {

// One way of coding a segment's operator and residuals, with what the decoder rebuilds the
// operator from besides the header. The dequantised residuals are not kept: the payload holds
// them, and the fallback decodes them again only while it measures this coding (a V×r matrix per
// coding would be the largest buffer of the encoder's peak).
struct SegmentCoding {
  format::SegmentHeader header;  // its operator and residual step
  std::vector<uint8_t> operator_payload;
  std::vector<uint8_t> residual_payload;
  std::vector<int64_t> edge_weights;  // ddl: the coded weights
  FramePositionsD reference_frame;    // geometric operators: the decoded reference frame
  // The fallback's measurement of it (STED of the sampled frames); NaN when not measured.
  double sted = std::numeric_limits<double>::quiet_NaN();

  size_t payload_bytes() const { return operator_payload.size() + residual_payload.size(); }
};

// Codes the residuals of the operator `target` names (its header, edge weights or reference
// frame) for the segment's coefficients: δ = L·C, quantised with target.header's step.
using WriteResidualsFn = std::function<StatusOr<std::vector<uint8_t>>(const SegmentSyntax&)>;

// The fallback's measurement frames of a segment, taken before its trajectories are released,
// and the meter that measures decodings of them. Not movable: the meter points to `original`.
struct MeasuredFrames {
  std::vector<int> frames;               // indices within the segment
  MeshSequence original;                 // those frames of the input, in codec vertex order
  std::optional<DistortionMeter> meter;  // none when they have no STED (e.g. all edges zero)

  MeasuredFrames() = default;
  MeasuredFrames(const MeasuredFrames&) = delete;
  MeasuredFrames& operator=(const MeasuredFrames&) = delete;
};

// Every k-th frame of the segment (all of them up to `max_frames`), in codec vertex order.
std::unique_ptr<MeasuredFrames> SampleMeasuredFrames(const SegmentTrajectories& trajectories,
                                                     const Triangles& triangles, int max_frames);

// Fitted DDL weights cost side information (about 10 bits per vertex per segment at 2^-7); on a
// short segment they may not pay for themselves. With options.ddl_dead_zone = 0 the encoder codes
// both the fitted weights (plain rounding) and the predicted weights alone (dead zone ∞: every
// residual 0, nearly free) with the residuals each implies, and keeps the smaller. At the same
// residual step the two reconstructions measured within 5 % STED of each other (samba 0.0233 vs
// 0.0245, crane 0.0371 vs 0.0369), so rate decides. (A Lagrangian cost with the coefficient error
// as distortion was tried and rejected: that error follows KG, not STED, and picked the predicted
// weights on samba, where the fitted ones win both rate and STED.) A fixed dead zone codes once.
// Only the smallest coding so far is kept (the first on ties).
StatusOr<SegmentCoding> ChooseDdlWeights(const std::vector<double>& fitted,
                                         const MeshTopology& topology,
                                         const EncoderOptions& options,
                                         format::WeightPrediction mode,
                                         const format::SegmentHeader& header,
                                         const WriteResidualsFn& write_residuals);

// The fallback's other candidates for a segment whose ddl coding is done: kirchhoff, tutte and
// mean-value, in this order, each with its residuals coded (a candidate whose residuals cannot be
// coded, e.g. beyond the format's range at this step, is left out). Kirchhoff's rows sum to the
// vertex degree, not 1, so its δ are about mean degree times larger: its residual step is scaled
// by the mean degree to reach a comparable distortion. Mean-value's weights come from the
// segment's mean shape, coded as the reference frame at ReferenceFrameStep(reference_step). A
// candidate whose step is beyond the format's range is left out too. Every candidate shares
// the ddl coding's mean, basis and anchors. This is the only step that needs the segment's
// coefficients: the caller releases them before the candidates are measured. With `only`, that
// candidate alone.
std::vector<SegmentCoding> CodeFallbackCandidates(const format::SegmentHeader& ddl_header,
                                                  const MeshTopology& topology,
                                                  const Eigen::MatrixXd& mean_shape,
                                                  double reference_step,
                                                  const WriteResidualsFn& write_residuals,
                                                  std::optional<OperatorId> only = std::nullopt);

// The normal matrix's factorisation of a measured coding, with what it was built from: a lower
// rank coded with the same operator and weights reuses it (the anchors, and mean-value's
// reference frame, the segment's mean shape, are the same at every rank).
struct MeasuredFactor {
  uint8_t operator_id = 0;
  std::vector<int64_t> edge_weights;
  std::optional<AnchoredLaplacianSolver> solver;

  bool Fits(const SegmentCoding& coding) const {
    return solver && coding.header.operator_id == operator_id &&
           coding.edge_weights == edge_weights;
  }
};

// How ChooseSegmentOperator measures.
struct OperatorChoiceOptions {
  // Candidates whose payload bits exceed the smallest candidate's by more than kStedSlopeBits ·
  // V · F · ln(ratio) are not measured (they would need a STED `ratio` times lower to win); 0 =
  // every candidate measured.
  double prune_sted_ratio = 0.0;
  // Whether the chosen coding needs its STED (the rank search compares it); without it a sole
  // remaining candidate is not measured.
  bool need_sted = true;
  // A factorisation to reuse for codings it fits (MeasuredFactor::Fits), or nullptr.
  const MeasuredFactor* factor = nullptr;
  // Where to keep the chosen coding's factorisation, or nullptr.
  MeasuredFactor* keep_factor = nullptr;
};

// The ddl operator's fallback. Fitted weights are side information (about 10 bits per vertex per
// segment) that only pays when the segment is long enough; the combinatorial operators need none
// and mean-value needs a coded reference frame. So the segment is also coded with the other
// candidates (CodeFallbackCandidates), each decoded as the decoder would and measured, and the
// coding with the lowest cost bits + kStedSlopeBits · V · F · ln STED is kept (the earlier on
// ties, so the DDL first). `shared` holds what every coding shares (mean, basis, anchors and
// their values); codings[0] is the DDL's when there is one. The residuals of one coding at a time
// are decoded from its payload, the decoder's own values, so only one candidate's deltas exist
// at once. A coding the decoder would reject is never chosen: fitted DDL weights can leave the
// normal matrix LᵀL + anchors singular (not positive definite), and then the next candidate that
// decodes is taken, those rate alone ruled out included. When the first coding that decodes has
// no STED, it is kept. kNumericalFailure (or the decoder's error) when no candidate decodes.
StatusOr<SegmentCoding> ChooseSegmentOperator(const MeasuredFrames& measured,
                                              const MeshTopology& topology,
                                              const std::vector<int32_t>& vertex_order,
                                              const SegmentSyntax& shared,
                                              std::vector<SegmentCoding> codings,
                                              const OperatorChoiceOptions& choice);

// Whether the decoder's normal matrix of an operator is positive definite whatever the segment:
// kirchhoff's and tutte's weights are positive on every edge, so LᵀL is singular only on the
// constants of each component, which the anchors (one at least per component) remove.
bool FactorsByConstruction(uint8_t operator_id);

// What the decoder would report when it rebuilds, factors and solves `coding` (with `shared`'s
// anchors): OK for a coding it decodes. Needed for codings no measurement decoded.
Status CheckCodingDecodes(const MeshTopology& topology, const std::vector<int32_t>& vertex_order,
                          const SegmentSyntax& shared, const SegmentCoding& coding);

// The grid step of a reference frame: `step` (the diagonal · 2^-reference_bits), or coarser when
// the frame lies so far from the origin that its coordinates would exceed the format's 2^40 steps.
double ReferenceFrameStep(const Eigen::MatrixXd& frame, double step);

}  // namespace dmc

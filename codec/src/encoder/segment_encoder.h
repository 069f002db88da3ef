// Encodes one segment of a stream: trajectory PCA, basis, anchors, the operator (with the ddl
// operator's weight choice, fallback and rank search) and the residuals, in closed loop: every
// quantity after a quantiser uses the decoder's reconstruction of it.
#pragma once

#include <cstdint>
#include <vector>

#include "bitstream/format.h"
#include "bitstream/syntax.h"
#include "dmc/encoder.h"
#include "dmc/topology.h"
#include "dmc/wire_ids.h"
#include "encoder/operator_choice.h"
#include "encoder/search_plan.h"
#include "entropy/byte_io.h"
#include "fitting/segment_pca.h"

namespace dmc {

// What a coded segment added to the stream.
struct SegmentResult {
  format::ChunkSizes sizes;                   // its six chunks' bytes, framing included
  OperatorId operator_id = OperatorId::kDdl;  // what the segment was coded with
  int rank = 0;
  int anchors = 0;
  double residual_step = 0.0;  // the segment header's, as coded (kirchhoff scales it)
};

class SegmentEncoder {
 public:
  // What every segment of one stream shares. `topology`, `triangles` (the codec's labels),
  // `vertex_order` (the residual coding order) and `options` are referenced and must outlive the
  // encoder; `operator_id` is options.operator_name's.
  SegmentEncoder(const MeshTopology& topology, const Triangles& triangles,
                 const std::vector<int32_t>& vertex_order, const EncoderOptions& options,
                 OperatorId operator_id, double diagonal, double residual_step);

  // Appends the segment's six chunks (segment header, mean, basis, operator, anchors, residuals)
  // to `out`. `trajectories` are the segment's frames starting at `first_frame`, in codec vertex
  // order. Const and without shared state: segments may be encoded concurrently, and the bytes do
  // not depend on the thread count. Each large buffer is released as soon as nothing after it
  // needs it, so the peak is the largest single step's: the PCA's eigenvectors once the basis is
  // coded, the trajectories once projected, the fitted operator once its weights are coded, and
  // the coefficients once every candidate's residuals are coded.
  StatusOr<SegmentResult> Encode(SegmentTrajectories trajectories, int first_frame,
                                 ByteWriter& out) const;

 private:
  struct Segment;
  struct RankCoding;

  format::SegmentHeader BaseHeader(int first_frame, int frame_count) const;
  std::vector<int> CandidateRanks(const Eigen::VectorXd& eigenvalues, int max_rank,
                                  int vertex_count) const;
  StatusOr<SegmentCoding> CodeDdlWeights(Segment& segment, Eigen::MatrixXd& coefficients,
                                         bool top) const;
  StatusOr<Segment> Prepare(SegmentTrajectories trajectories, int first_frame) const;
  StatusOr<RankCoding> CodeAtRank(Segment& segment, int rank, int next_rank) const;
  Eigen::MatrixXd SolveCoefficients(Segment& segment, int rank, int next_rank) const;
  Status CodeDdl(Segment& segment, Eigen::MatrixXd& coefficients, int next_rank, bool top,
                 RankCoding& coding) const;
  StatusOr<SegmentCoding> DecodableCoding(const Segment& segment, SegmentCoding ddl,
                                          const Eigen::MatrixXd& coefficients) const;
  Status CodeFixedOperator(Segment& segment, int rank, const Eigen::MatrixXd& coefficients,
                           RankCoding& coding) const;
  WriteResidualsFn ResidualWriter(const Segment& segment,
                                  const Eigen::MatrixXd& coefficients) const;
  SegmentResult AppendChunks(const Segment& segment, const RankCoding& coding,
                             ByteWriter& out) const;

  const MeshTopology& topology_;
  const Triangles& triangles_;
  const std::vector<int32_t>& vertex_order_;
  const EncoderOptions& options_;
  OperatorId operator_id_;
  double diagonal_;
  double residual_step_;
  format::WeightPrediction weight_prediction_;
  SearchPlan plan_;  // EncoderOptions::effort and the switches that restrict it
};

}  // namespace dmc

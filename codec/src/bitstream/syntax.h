// Deterministic pieces of the segment syntax that the encoder and decoder must compute
// identically: chunk checksums, vertex coding order, the DDL weight schedule and prediction, and
// context selection. All integer or exactly specified; normative in bitstream-spec/dmc-format.md.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bitstream/format.h"
#include "dmc/topology.h"
#include "entropy/adaptive_bit.h"

namespace dmc::format {

// XXH32 of a chunk payload, seeded with chunk_type + 256 · version_minor (the stream's, §4.2):
// 1.0 streams seed with the type alone, and a stream whose minor version byte was changed fails
// every checksum instead of being read with another version's syntax.
uint32_t ChunkChecksum(uint8_t chunk_type, std::span<const uint8_t> payload,
                       uint8_t version_minor = kVersionMinor);

// Vertex coding order: breadth-first search over one-rings (neighbours in ascending index order),
// starting from the lowest-index unvisited vertex, until every vertex is visited.
std::vector<int32_t> BreadthFirstOrder(const MeshTopology& topology);

// The DDL weight schedule: vertices are visited by decreasing number of already-known incident
// edge weights (ties: lowest vertex index); at its visit a vertex's still-unknown edges (in
// one-ring order) are coded, all but the last explicitly, the last implied by the unit sum.
struct WeightVisit {
  int32_t vertex;
  std::vector<int32_t> unknown_edges;  // edge indices; the last one is implied
};
std::vector<WeightVisit> BuildWeightSchedule(const MeshTopology& topology);

// How an explicit DDL weight is predicted from the unit-sum constraint (frozen values):
//  kUniform (thesis 5.4): p = (S - K) / n, the remaining sum shared equally among the n unknown
//    edges of the vertex (S = 2^weight_bits, K = sum of its known weights).
//  kReferenceProportional: p = (S - K) * r_e / sum of r_u over the n unknown edges, the remaining
//    sum shared in proportion to a connectivity-only reference weight r (ReferenceWeight). When the
//    fit is pulled toward that reference the residuals vanish, so the weight cost falls smoothly
//    to zero as the DDL approaches the combinatorial operator.
enum class WeightPrediction : uint8_t { kUniform = 0, kReferenceProportional = 1 };

// Reference weight of an edge (i, j) in 2^-20 units: floor(2^20 (d_i + d_j) / (2 d_i d_j)), the
// symmetric mean of the Tutte weights 1/d_i and 1/d_j (d = vertex degree).
int64_t ReferenceWeight(const MeshTopology& topology, int edge);

// Prediction of the weight of unknown_edges[0] given the remaining sum S - K; `unknown_edges` are
// the vertex's still-unknown edges, the one to predict first.
int64_t PredictWeight(WeightPrediction mode, int64_t remaining, const MeshTopology& topology,
                      std::span<const int32_t> unknown_edges);

// Rounded integer division a / b for b > 0, halves rounded towards +infinity:
// floor((2a + b) / (2b)).
int64_t RoundDiv(int64_t numerator, int64_t denominator);

// Context sets for the quantised delta-trajectories: by PCA component and by the activity of the
// already coded neighbours in the same component.
inline constexpr int kResidualColumnGroups = 24;
inline constexpr int kResidualActivityBuckets = 5;
int ResidualColumnGroup(int column);
// mean |q| over coded neighbours, bucketed: 0 if none or all zero, else min(4, bit_width of
// the rounded mean absolute value ((2*sum + n) / (2n)) + 1).
int ResidualActivityBucket(int64_t abs_sum, int coded_neighbours);

// The residual context of the i-th vertex in coding order is the activity bucket of the |q| of its
// one-ring neighbours already coded in the same column (coding position < i), counted in ring
// order with repeats. Which neighbours those are is the same in every column, so both sides list
// their coding positions once per segment and keep each column's values by coding position.
struct EarlierNeighbours {
  std::vector<int32_t> offsets;    // vertex i's entries: positions[offsets[i] .. offsets[i + 1])
  std::vector<int32_t> positions;  // coding positions of earlier-coded ring neighbours

  // Bucket of the i-th vertex from the column's values by coding position (q[p] for p < i).
  int Bucket(const std::vector<int64_t>& q, int i) const {
    int64_t abs_sum = 0;
    for (int32_t e = offsets[i]; e < offsets[i + 1]; ++e) {
      const int64_t n = q[positions[e]];
      abs_sum += n < 0 ? -n : n;
    }
    return ResidualActivityBucket(abs_sum, offsets[i + 1] - offsets[i]);
  }
};
// `vertex_order` lists the vertices in coding order (a permutation of [0, V)).
EarlierNeighbours ListEarlierNeighbours(const MeshTopology& topology,
                                        std::span<const int32_t> vertex_order);

// Format 1.1 (spec §8.6): the context of a residual is chosen by an activity estimate that
// weighs the mean |q| of the earlier-coded neighbours in the same column (weight 2) with two
// decayed histories of the same vertex's |q| over the previous columns (weight 1 each), in
// 1/16 units, every |q| clamped to kResidualActivityClamp (m = 16·min(|q|, clamp)):
//   after column k: fast = k = 0 ? m : (fast + m) >> 1, slow = k = 0 ? m : (3·slow + m) >> 2;
//   activity = floor((floor(32·S / n) + fast + slow) / (2·[n > 0] + 2·[k ≥ 1])), 0 if the divisor
//   is 0, a term taking part only when its condition holds (S the clamped |q| summed over the n
//   earlier-coded neighbours);
//   context = 2·min(kResidualActivityOctaves - 1, bit_width(activity)) + [n > 0 and S = 0].
inline constexpr int kResidualActivityOctaves = 10;
inline constexpr int kResidualContextsPerGroup11 = 2 * kResidualActivityOctaves;
inline constexpr int64_t kResidualActivityClamp = int64_t{1} << 16;
// The vertex's histories after a column with magnitude `q_abs` (column 0 starts them).
inline void UpdateResidualHistories(int column, int64_t q_abs, uint32_t& fast, uint32_t& slow) {
  const auto m =
      static_cast<uint32_t>(16 * (q_abs < kResidualActivityClamp ? q_abs : kResidualActivityClamp));
  fast = column == 0 ? m : (fast + m) >> 1;
  slow = column == 0 ? m : (3 * slow + m) >> 2;
}
// `earlier_sum`: the clamped |q| summed over the `earlier_count` earlier-coded neighbours in
// `column`; `fast` and `slow`: the vertex's histories (ignored in column 0).
int ResidualContext11(int column, int64_t earlier_sum, int earlier_count, uint32_t fast,
                      uint32_t slow);

inline constexpr int kResidualContextsPerGroup =
    kResidualContextsPerGroup11 > kResidualActivityBuckets ? kResidualContextsPerGroup11
                                                           : kResidualActivityBuckets;
struct ResidualContexts {
  // 1.0 uses sets[g][0 .. kResidualActivityBuckets), 1.1 sets[g][0 .. kResidualContextsPerGroup11).
  IntegerContexts sets[kResidualColumnGroups][kResidualContextsPerGroup];
};

// The context selection of the residual chunk, the one place the writer and the reader share:
// per segment, for the stream's minor version. Values are coded column by column (k = 0 .. r-1),
// each column over the vertices in coding order (i = 0 .. V-1); before coding the value of
// (k, i) call Select(k, i), after it Record(k, i, q). Select may be called more than once for the
// same (k, i) (an encoder weighing candidate values); it does not change the state.
class ResidualContextSelector {
 public:
  ResidualContextSelector(const MeshTopology& topology, std::span<const int32_t> vertex_order,
                          uint8_t version_minor);

  IntegerContexts& Select(int column, int i) {
    auto& sets = contexts_->sets[ResidualColumnGroup(column)];
    return sets[minor_ == 0 ? earlier_.Bucket(current_, i) : Context11(column, i)];
  }
  // Exactly once per value, after it is coded.
  void Record(int column, int i, int64_t q) {
    const int64_t q_abs = q < 0 ? -q : q;
    current_[i] = q_abs;
    if (minor_ >= 1) UpdateResidualHistories(column, q_abs, fast_[i], slow_[i]);
  }

 private:
  int Context11(int column, int i) const;

  uint8_t minor_;
  EarlierNeighbours earlier_;
  // |q| by coding position in the current column (positions < i recorded so far; the rest hold
  // the previous column's, never read).
  std::vector<int64_t> current_;
  // 1.1: the histories by coding position, over the columns before the current one (and, for
  // positions < i, the current one).
  std::vector<uint32_t> fast_, slow_;
  std::unique_ptr<ResidualContexts> contexts_;
};

inline constexpr int kBasisColumnGroups = 16;
struct BasisContexts {
  AdaptiveBit second_order[kBasisColumnGroups];  // 1.0: the column's predictor
  IntegerContexts first[kBasisColumnGroups];
  IntegerContexts delta[kBasisColumnGroups];
  // 1.1: the column's bit depth (difference from the previous column's) and predictor.
  IntegerContexts depth;
  AdaptiveBit predictor_high[kBasisColumnGroups];
  AdaptiveBit predictor_low[kBasisColumnGroups][2];
};

// 1.1 basis syntax (spec §8.3). A column's bit depth lies in [kMinBasisBits, header basis_bits].
inline constexpr int kMinBasisBits = 2;
inline constexpr int kBasisPredictors = 4;
// Context group of a column: its bit depth - kMinBasisBits, at most kBasisColumnGroups - 1.
int BasisContextGroup(int column, int depth);
// Prediction of sample f of one axis of a column from its earlier samples s[0..f): mode 0 none,
// 1 the previous sample, 2 linear extrapolation, 3 half the linear slope.
inline int64_t PredictBasisSample(int mode, const int64_t* s, int f) {
  if (f == 0 || mode == 0) return 0;
  if (f == 1 || mode == 1) return s[f - 1];
  if (mode == 2) return 2 * s[f - 1] - s[f - 2];
  return (3 * s[f - 1] - s[f - 2]) >> 1;
}
// The predictor mode as two decisions: mode >> 1 (predictor_high[g]), then mode & 1
// (predictor_low[g][mode >> 1]).
template <typename CodeBit>
void EncodeBasisPredictor(BasisContexts& contexts, int g, int mode, CodeBit&& code) {
  code(contexts.predictor_high[g], mode >> 1);
  code(contexts.predictor_low[g][mode >> 1], mode & 1);
}

// Weight residual contexts by the number of still-unknown edges at prediction time (1..4+).
struct WeightContexts {
  IntegerContexts by_unknown[4];
};

struct AnchorContexts {
  IntegerContexts index_gap;
  IntegerContexts value[kBasisColumnGroups];
  IntegerContexts step_exponent;  // 1.2
};

// Format 1.2 step shaping (spec §8.5.1). 2^(e / kStepExponentsPerOctave) for |e| ≤
// kMaxStepExponent, the same double on every platform (a frozen table scaled by a power of two).
double StepFactor(int exponent);
// The residual step factor of every vertex: each vertex belongs to the region of the anchor
// nearest to it in one-ring hops (ties: the anchor listed first) and takes that anchor's factor;
// a vertex no anchor reaches takes 1. Which anchor owns a vertex does not depend on the ring
// order. Empty when every exponent is 0 (every factor 1, as in streams before 1.2).
std::vector<double> VertexStepFactors(const MeshTopology& topology,
                                      std::span<const int32_t> anchors,
                                      std::span<const int8_t> exponents);
// The residual step of vertex v: residual_step · factors[v], or residual_step when `factors` is
// empty. The one product the writer, the reader and the syntax digest all use (§8.6, §12.2).
inline double VertexResidualStep(double residual_step, std::span<const double> factors, int v) {
  return factors.empty() ? residual_step : residual_step * factors[v];
}
// The anchor owning each vertex under that rule, -1 for a vertex no anchor reaches (as positions
// in `anchors`). The encoder uses it to fit the exponents.
std::vector<int32_t> AnchorRegions(const MeshTopology& topology, std::span<const int32_t> anchors);

// Whether a segment may name `operator_id`, and whether its operator chunk then carries a
// reference frame: the codec() and geometric() of its kOperatorTraits row (dmc/operator_traits.h).
bool IsCodecOperator(uint8_t operator_id);
bool IsGeometricOperator(uint8_t operator_id);

// Reference frame coding: vertices in BreadthFirstOrder; each coordinate is an integer on the grid
// of the chunk's step, predicted by the rounded mean (RoundDiv) of the already decoded one-ring
// neighbours, or by the previously decoded vertex when none is decoded yet (0 for the first).
struct ReferenceFrameContexts {
  IntegerContexts with_neighbours[3];
  IntegerContexts without_neighbours[3];
};

// The reference frame's prediction (spec §8.4), walked the same way by the writer and the reader:
// vertices in BreadthFirstOrder; each axis of a vertex is predicted by the RoundDiv mean of its
// already-coded one-ring neighbours' values, or, when none is coded yet, by the previous vertex's
// (0 for the first). Use: for v in order(): Predict(v), code or decode v's three values against
// the prediction, Record(v, values).
class ReferenceFramePredictor {
 public:
  explicit ReferenceFramePredictor(const MeshTopology& topology);
  const std::vector<int32_t>& order() const { return order_; }
  // The prediction of vertex v; true when it comes from coded neighbours (the context set then
  // is with_neighbours).
  bool Predict(int v, std::array<int64_t, 3>* prediction) const;
  void Record(int v, const std::array<int64_t, 3>& values);
  // Every vertex's recorded values, by vertex index.
  const std::vector<std::array<int64_t, 3>>& values() const { return values_; }

 private:
  const MeshTopology& topology_;
  std::vector<int32_t> order_;
  std::vector<uint8_t> coded_;
  std::vector<std::array<int64_t, 3>> values_;
  std::array<int64_t, 3> previous_ = {0, 0, 0};
};

struct MeanContexts {
  IntegerContexts first;
  IntegerContexts delta;
};

}  // namespace dmc::format

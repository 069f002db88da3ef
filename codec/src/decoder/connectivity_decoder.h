// Decoding of the connectivity chunk, and the deterministic pieces of the connectivity syntax that
// the encoder (encoder/connectivity_encoder.h) must compute exactly as the decoder does.
//
// Payload syntax (normative; every method starts with its wire byte):
//   method 0, kIndexed: the range-coded triangle list in input order (first index as a delta from
//     the previous triangle's first index, the two others as deltas from the first, one
//     IntegerContexts set per corner).
//   method 1, kDracoWithVertexOrder: varint n, then n bytes of a Draco mesh buffer (see below),
//     then u8 label model (LabelModel), then the range-coded vertex labels: the decoded
//     Draco point p becomes output vertex label[p], which restores the input vertex order.
//   method 2, kDracoReordered: varint n, then n bytes of a Draco mesh buffer; output vertex p is
//     Draco's point p (the stream header says the order is the codec's own).
// The Draco buffer is Draco bitstream 2.2, a triangular mesh coded with edgebreaker (standard or
// valence traversal), no metadata, one 1-component uint8 POSITION attribute whose values are all
// zero (Draco needs a position attribute to build its corner table; its values carry nothing).
// The decoder checks the Draco header and its vertex and face counts against the sequence header
// before letting Draco allocate anything.
//
// Vertex labels (method 1) are coded in LabelCodingOrder over the decoded Draco mesh. For each
// vertex v a prediction y is formed from the labels already decoded (PredictLabel); what is sent is
// the signed difference of ranks among the labels not yet used,
//   r = #{unused labels < label[v]} - #{unused labels < y},
// with one adaptive IntegerContexts set per LabelContext. Coding ranks rather than label
// differences never spends code space on labels that are already taken.
//
// Format 1.1 adds label kernels (LabelModel::kernel_radius > 0): a vertex with decoded
// neighbours first codes whether its label is a kernel candidate, an unused label within the
// kernel radius of a decoded neighbour's label (LabelKernel). Candidates are weighted by an
// adaptive histogram of the label differences seen between neighbours, and a hit is coded by
// binary splits of the candidate list with those weights; a miss (an escape) falls back to the
// rank difference above.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "bitstream/format.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/wire_ids.h"

namespace dmc {

// Wire values of the connectivity methods: the frozen IDs of dmc/wire_ids.h.
using ConnectivityCoding = ConnectivityMethod;

// Decodes a connectivity payload into the triangle list of the output vertex order. Safe on
// untrusted input: sizes, counts and indices are checked before use; any inconsistency is
// kCorruptStream (kTruncatedStream when the payload ends early) naming the element at fault, and
// Draco failures are reported as kCorruptStream with Draco's message. The result always has
// exactly `triangle_count` triangles with indices in [0, vertex_count). `version_minor` is the
// stream's (preamble, §4.1): the syntax of the payload it selects.
StatusOr<Triangles> DecodeConnectivity(std::span<const uint8_t> payload, uint32_t vertex_count,
                                       uint32_t triangle_count,
                                       uint8_t version_minor = format::kVersionMinor);

namespace connectivity {

// Label predictors a method-1 payload may select (wire values).
enum class LabelPredictor : uint8_t {
  kNeighborMedian = 0,  // lower median of the distinct decoded neighbours' labels
  kParallelogram = 1,   // lower median of label[a] + label[b] - label[c] over the triangles
                        // (v, a, b) with a and b decoded and every other triangle (a, b, c)
                        // with c decoded; kNeighborMedian when there is none. Edges ab where
                        // both a and b lie in more than kMaxParallelogramScan triangles are
                        // skipped (bounds the work on crafted streams).
};
inline constexpr int kLabelPredictorCount = 2;
inline constexpr size_t kMaxParallelogramScan = 64;

// How a method-1 payload codes labels. Wire byte: bit 0 the predictor, bit 1 spread_contexts,
// bits 2-3 the kernel radius code (format 1.1 only; 0 in 1.0), the other bits 0. Which model is
// smallest depends on how the input was labelled (measured: kNeighborMedian wins on samba, crane,
// horse, chicken; kParallelogram on dance and cow; spread contexts gain 3-10% on horse, jump and
// elephant and lose up to 2% elsewhere), so the encoder tries them all.
struct LabelModel {
  LabelPredictor predictor = LabelPredictor::kNeighborMedian;
  bool spread_contexts = false;  // split contexts by the spread of the neighbours' labels
  uint8_t kernel_code = 0;       // 0: no kernel; 1, 2, 3: kernel radius kKernelRadii[code]

  uint8_t wire() const {
    return static_cast<uint8_t>(static_cast<uint8_t>(predictor) | (spread_contexts ? 2 : 0) |
                                (kernel_code << 2));
  }
  static LabelModel FromWire(uint8_t wire) {
    return {static_cast<LabelPredictor>(wire & 1), (wire & 2) != 0,
            static_cast<uint8_t>((wire >> 2) & 3)};
  }
};
// Label model wire values a stream may use: below kLabelModelCount in 1.0, below
// kLabelModelCount11 from 1.1 on.
inline constexpr int kLabelModelCount = 2 * kLabelPredictorCount;
inline constexpr int kLabelModelCount11 = 4 * kLabelModelCount;
int LabelModelCount(uint8_t version_minor);

// Kernel radii by kernel code (code 0: no kernel). Which one wins depends on how far apart the
// input labels of neighbours are (measured: 16 on dance, cow and jump, 256 on the Vlasic meshes).
inline constexpr std::array<int32_t, 4> kKernelRadii = {0, 16, 64, 256};
// At most this many decoded neighbours (the first in ascending point order) are kernel centres.
inline constexpr size_t kMaxKernelCenters = 16;
// Histogram: every bin starts at 1 and gains kKernelIncrement per observed difference; when the
// bins sum to more than kKernelHalvingTotal they are all halved (rounding up).
inline constexpr uint32_t kKernelIncrement = 8;
inline constexpr uint64_t kKernelHalvingTotal = uint64_t{1} << 24;
// Escape flag contexts, by min(number of centres, kKernelEscapeContexts).
inline constexpr int kKernelEscapeContexts = 4;

// The kernel model of a payload: the adaptive histogram of label differences and, for the
// vertex being coded, its weighted candidate labels. Encoder and decoder use it identically.
class LabelKernel {
 public:
  LabelKernel(int32_t radius, int32_t label_count);

  // The candidates for these centre labels (decoded neighbour labels): every label not yet used
  // (used[label] == 0) within the radius of a centre, ascending, each weighted by the sum over
  // centres c within the radius of bin[label - c].
  void Build(std::span<const int32_t> centers, std::span<const uint8_t> used);
  const std::vector<int32_t>& candidates() const { return candidates_; }
  // Index of `label` among the candidates, or -1.
  int32_t Find(int32_t label) const;
  // P(bit = 0) of the split of candidates [lo, hi) at mid = (lo + hi) / 2, in units of 2^-16,
  // clamped to [15, 65521]; bit 0 means the label is in [lo, mid).
  uint32_t SplitP0(int32_t lo, int32_t hi) const;
  // Adds the differences label - c of the centres within the radius to the histogram.
  void Update(std::span<const int32_t> centers, int32_t label);

 private:
  int32_t radius_;
  std::vector<uint64_t> bins_;    // size 2 * radius + 1; bin d + radius counts difference d
  uint64_t total_ = 0;            // sum of bins_
  std::vector<uint64_t> weight_;  // per label, scratch (zero outside Build's candidates)
  std::vector<int32_t> candidates_;
  std::vector<int32_t> sorted_centers_;  // scratch of Build
  std::vector<uint64_t> prefix_;         // prefix_[i] = sum of the first i candidates' weights
};

// Kinds of prediction; each has its own adaptive contexts.
enum class PredictionKind : uint8_t {
  kNoNeighbor = 0,  // no decoded neighbour: previous decoded label + 1 (0 for the first vertex)
  kNeighborMedian = 1,
  kParallelogram = 2,
};
inline constexpr int kPredictionKindCount = 3;

// Vertex-to-triangle incidence of a triangle list in CSR form: all label coding needs to walk
// the decoded mesh (much cheaper to build than a MeshTopology). Indices must be in range; the
// adjacency refers to `triangles`, which must outlive it.
class TriangleAdjacency {
 public:
  TriangleAdjacency(const Triangles& triangles, int32_t vertex_count);

  int32_t vertex_count() const { return static_cast<int32_t>(offsets_.size()) - 1; }
  const Triangles& triangles() const { return triangles_; }
  // The triangles incident to v, ascending.
  std::span<const int32_t> TrianglesOf(int32_t v) const {
    return {faces_.data() + offsets_[v], faces_.data() + offsets_[v + 1]};
  }
  // The distinct neighbours of v, ascending, written to `out` (cleared first).
  void Neighbors(int32_t v, std::vector<int32_t>& out) const;

 private:
  const Triangles& triangles_;
  std::vector<int32_t> offsets_;  // size V + 1
  std::vector<int32_t> faces_;    // size 3T
};

// The order in which method 1 codes labels: repeatedly the uncoded vertex with the most coded
// neighbours, ties to the lowest index (Draco's point order follows its traversal, so this
// stays in the oldest part of the front); when no uncoded vertex has a coded neighbour, the
// lowest-index uncoded vertex. Many coded neighbours make predictions reliable. (Measured on
// samba: 2.5% fewer label bits than first-come or last-come tie breaking.)
std::vector<int32_t> LabelCodingOrder(const TriangleAdjacency& adjacency);

struct LabelPrediction {
  int64_t label = 0;  // clamped to [0, V)
  PredictionKind kind = PredictionKind::kNoNeighbor;
  // Smallest and largest label of the decoded neighbours (-1 when there is none).
  int32_t neighbor_min = -1;
  int32_t neighbor_max = -1;
};

// Predicts the label of vertex v. `labels[u]` is u's label if u is already decoded, else -1;
// `previous_label` is the last decoded label (-1 before the first). `scratch` is reused storage.
LabelPrediction PredictLabel(const TriangleAdjacency& adjacency, std::span<const int32_t> labels,
                             int32_t v, LabelPredictor predictor, int32_t previous_label,
                             std::vector<int64_t>& scratch);

// The set of labels 0..n-1 not yet used, with rank and selection in O(log n) (a Fenwick tree).
class UnusedLabels {
 public:
  explicit UnusedLabels(int32_t label_count);

  int32_t remaining() const { return remaining_; }
  // Number of unused labels smaller than `label` (label in [0, n]).
  int32_t Rank(int64_t label) const;
  // The unused label with `rank` unused labels below it; rank must be in [0, remaining()).
  int32_t Select(int32_t rank) const;
  // Marks an unused label as used.
  void Remove(int32_t label);

 private:
  std::vector<int32_t> tree_;  // 1-based Fenwick tree of 0/1 flags
  int32_t remaining_ = 0;
  int32_t top_bit_ = 0;  // largest power of two <= n, for Select's descent
};

// Context sets: per prediction kind, and with spread contexts also per spread bucket
// min(bit_width(s) / 2, kSpreadBuckets - 1), where s is the number of unused labels between the
// smallest and the largest decoded neighbour label (a wide spread foretells a large error).
inline constexpr int kSpreadBuckets = 6;
inline constexpr int kLabelContextCount = kPredictionKindCount * kSpreadBuckets;
int LabelContext(const LabelPrediction& prediction, const UnusedLabels& unused,
                 bool spread_contexts);

// The kernel centres of v: the labels of its first kMaxKernelCenters decoded neighbours in
// ascending point order (`neighbors` is scratch), written to `out` (cleared first).
void KernelCenters(const TriangleAdjacency& adjacency, std::span<const int32_t> labels, int32_t v,
                   std::vector<int32_t>& neighbors, std::vector<int32_t>& out);

// Decodes the Draco buffer of a method-1/2 payload into its faces over Draco's points, after
// checking the Draco header and its counts against the expected ones. When `point_values` is not
// null it receives, per decoded point, the index of its POSITION attribute value: the encoder
// maps that back to its input vertex.
StatusOr<Triangles> DecodeDracoTriangles(std::span<const uint8_t> draco_buffer,
                                         uint32_t vertex_count, uint32_t triangle_count,
                                         std::vector<int32_t>* point_values = nullptr);

}  // namespace connectivity
}  // namespace dmc

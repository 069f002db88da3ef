#include "decoder/connectivity_decoder.h"

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <array>
#include <bit>
#include <functional>
#include <string>
#include <utility>

#include "decoder/range_decoder.h"
#include "entropy/byte_io.h"

namespace dmc {
namespace connectivity {
namespace {

// Draco bitstream 2.2 header of a triangular mesh coded with edgebreaker and no metadata:
// "DRACO", major 2, minor 2, geometry type 1 (TRIANGULAR_MESH), method 1 (MESH_EDGEBREAKER),
// u16 flags 0.
constexpr std::array<uint8_t, 11> kDracoHeader = {'D', 'R', 'A', 'C', 'O', 2, 2, 1, 1, 0, 0};
// Edgebreaker traversal decoders Draco may have chosen: standard (0) or valence (2).
constexpr uint8_t kDracoStandardTraversal = 0;
constexpr uint8_t kDracoValenceTraversal = 2;

std::string ToString(int64_t value) { return std::to_string(value); }

int64_t LowerMedian(std::vector<int64_t>& values) {
  const size_t middle = (values.size() - 1) / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle),
                   values.end());
  return values[middle];
}

StatusOr<Triangles> DecodeIndexed(std::span<const uint8_t> payload, uint32_t vertex_count,
                                  uint32_t triangle_count) {
  // Every triangle costs at least one coded bit, so a short payload cannot claim huge counts.
  if (triangle_count > 64 * payload.size() + 64) {
    return CorruptStreamError("triangle count " + ToString(triangle_count) +
                              " cannot fit in a connectivity payload of " +
                              ToString(static_cast<int64_t>(payload.size())) + " bytes");
  }
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(payload.subspan(1)));
  IntegerContexts first, second, third;
  Triangles triangles(triangle_count, 3);
  int64_t previous = 0;
  const int64_t v_count = vertex_count;
  for (uint32_t t = 0; t < triangle_count; ++t) {
    int64_t d0, d1, d2;
    DMC_RETURN_IF_ERROR(decoder.DecodeSigned(first, &d0));
    DMC_RETURN_IF_ERROR(decoder.DecodeSigned(second, &d1));
    DMC_RETURN_IF_ERROR(decoder.DecodeSigned(third, &d2));
    if (decoder.overrun()) break;  // reported below; stop before trusting garbage
    const int64_t a = previous + d0, b = a + d1, c = a + d2;
    if (a < 0 || a >= v_count || b < 0 || b >= v_count || c < 0 || c >= v_count) {
      return CorruptStreamError("triangle " + ToString(t) + " has a vertex index outside [0, " +
                                ToString(v_count) + ")");
    }
    triangles.row(t) << static_cast<int32_t>(a), static_cast<int32_t>(b), static_cast<int32_t>(c);
    previous = a;
  }
  DMC_RETURN_IF_ERROR(decoder.CheckNotOverrun("connectivity"));
  return triangles;
}

// Reads "varint n, n bytes" and returns the n bytes.
StatusOr<std::span<const uint8_t>> ReadDracoBuffer(ByteReader& reader) {
  uint64_t size;
  DMC_RETURN_IF_ERROR(reader.GetVarU(&size, "Draco buffer size"));
  if (size > reader.remaining()) {
    return TruncatedStreamError("Draco buffer of " + ToString(static_cast<int64_t>(size)) +
                                " bytes declared, " +
                                ToString(static_cast<int64_t>(reader.remaining())) + " present");
  }
  std::span<const uint8_t> buffer;
  DMC_RETURN_IF_ERROR(reader.GetBytes(size, &buffer, "Draco buffer"));
  return buffer;
}

StatusOr<Triangles> DecodeDracoReordered(std::span<const uint8_t> payload, uint32_t vertex_count,
                                         uint32_t triangle_count) {
  ByteReader reader(payload.subspan(1));
  DMC_ASSIGN_OR_RETURN(const std::span<const uint8_t> draco_buffer, ReadDracoBuffer(reader));
  if (!reader.at_end()) return CorruptStreamError("connectivity payload has trailing bytes");
  return DecodeDracoTriangles(draco_buffer, vertex_count, triangle_count);
}

StatusOr<Triangles> DecodeDracoWithVertexOrder(std::span<const uint8_t> payload,
                                               uint32_t vertex_count, uint32_t triangle_count,
                                               uint8_t version_minor) {
  const std::span<const uint8_t> body = payload.subspan(1);
  ByteReader reader(body);
  DMC_ASSIGN_OR_RETURN(const std::span<const uint8_t> draco_buffer, ReadDracoBuffer(reader));
  uint8_t model_value;
  DMC_RETURN_IF_ERROR(reader.GetU8(&model_value, "vertex label model"));
  if (model_value >= LabelModelCount(version_minor)) {
    return CorruptStreamError("vertex label model " + ToString(model_value) + " is unknown" +
                              (model_value < kLabelModelCount11 ? " in format 1.0" : ""));
  }
  const LabelModel model = LabelModel::FromWire(model_value);
  DMC_ASSIGN_OR_RETURN(Triangles draco_triangles,
                       DecodeDracoTriangles(draco_buffer, vertex_count, triangle_count));

  const int32_t v_count = static_cast<int32_t>(vertex_count);
  const TriangleAdjacency adjacency(draco_triangles, v_count);
  RangeDecoder decoder;
  DMC_RETURN_IF_ERROR(decoder.Init(body.subspan(reader.position())));
  std::array<IntegerContexts, kLabelContextCount> contexts;
  std::array<AdaptiveBit, kKernelEscapeContexts> escape_contexts;
  UnusedLabels unused(v_count);
  std::vector<int32_t> labels(v_count, -1);
  std::vector<uint8_t> used(model.kernel_code != 0 ? v_count : 0, 0);
  LabelKernel kernel(kKernelRadii[model.kernel_code], model.kernel_code != 0 ? v_count : 0);
  int32_t previous_label = -1;
  std::vector<int64_t> scratch;
  std::vector<int32_t> neighbors, centers;
  for (const int32_t v : LabelCodingOrder(adjacency)) {
    int32_t label = -1;
    if (model.kernel_code != 0) {
      KernelCenters(adjacency, labels, v, neighbors, centers);
      if (!centers.empty()) {
        kernel.Build(centers, used);
        const auto candidate_count = static_cast<int32_t>(kernel.candidates().size());
        const size_t escape_context = std::min(centers.size(), size_t{kKernelEscapeContexts}) - 1;
        if (candidate_count > 0 && decoder.DecodeBit(escape_contexts[escape_context]) == 0) {
          int32_t lo = 0, hi = candidate_count;
          while (hi - lo > 1) {
            AdaptiveBit split;  // a fixed probability: the model is never reused
            split.fast = split.slow = static_cast<uint16_t>(kernel.SplitP0(lo, hi));
            if (decoder.DecodeBit(split) == 0) {
              hi = lo + (hi - lo) / 2;
            } else {
              lo = lo + (hi - lo) / 2;
            }
          }
          if (decoder.overrun()) break;  // reported below as truncation
          label = kernel.candidates()[static_cast<size_t>(lo)];
        }
      }
    }
    if (label < 0) {
      const LabelPrediction prediction =
          PredictLabel(adjacency, labels, v, model.predictor, previous_label, scratch);
      int64_t rank_difference;
      DMC_RETURN_IF_ERROR(decoder.DecodeSigned(
          contexts[LabelContext(prediction, unused, model.spread_contexts)], &rank_difference));
      if (decoder.overrun()) break;  // reported below as truncation, not as a bad rank
      const int64_t rank = unused.Rank(prediction.label) + rank_difference;
      if (rank < 0 || rank >= unused.remaining()) {
        return CorruptStreamError("vertex label rank " + ToString(rank) + " of Draco point " +
                                  ToString(v) + " is outside [0, " + ToString(unused.remaining()) +
                                  ")");
      }
      label = unused.Select(static_cast<int32_t>(rank));
    }
    unused.Remove(label);
    labels[v] = label;
    previous_label = label;
    if (model.kernel_code != 0) {
      used[static_cast<size_t>(label)] = 1;
      if (!centers.empty()) kernel.Update(centers, label);
    }
  }
  DMC_RETURN_IF_ERROR(decoder.CheckNotOverrun("connectivity vertex labels"));

  // Labels are distinct by construction (each is selected among unused ones), so relabelling
  // keeps every triangle valid.
  Triangles triangles(draco_triangles.rows(), 3);
  for (Eigen::Index t = 0; t < draco_triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) triangles(t, k) = labels[draco_triangles(t, k)];
  }
  return triangles;
}

}  // namespace

TriangleAdjacency::TriangleAdjacency(const Triangles& triangles, int32_t vertex_count)
    : triangles_(triangles), offsets_(static_cast<size_t>(vertex_count) + 1, 0) {
  const auto t_count = static_cast<int32_t>(triangles.rows());
  for (int32_t t = 0; t < t_count; ++t) {
    for (int k = 0; k < 3; ++k) ++offsets_[triangles(t, k) + 1];
  }
  for (int32_t v = 0; v < vertex_count; ++v) offsets_[v + 1] += offsets_[v];
  faces_.resize(static_cast<size_t>(offsets_[vertex_count]));
  std::vector<int32_t> fill(offsets_.begin(), offsets_.end() - 1);
  for (int32_t t = 0; t < t_count; ++t) {  // ascending t, so each list comes out sorted
    for (int k = 0; k < 3; ++k) faces_[fill[triangles(t, k)]++] = t;
  }
}

void TriangleAdjacency::Neighbors(int32_t v, std::vector<int32_t>& out) const {
  out.clear();
  for (const int32_t t : TrianglesOf(v)) {
    for (int k = 0; k < 3; ++k) {
      if (triangles_(t, k) != v) out.push_back(triangles_(t, k));
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

std::vector<int32_t> LabelCodingOrder(const TriangleAdjacency& adjacency) {
  const int32_t v_count = adjacency.vertex_count();
  std::vector<int32_t> coded_neighbors(v_count, 0);
  std::vector<uint8_t> done(v_count, 0);
  std::vector<int32_t> order;
  order.reserve(v_count);
  // heaps[c]: a min-heap of the vertices that reached c coded neighbours; an entry is stale once
  // its vertex is done or has moved to a higher count. `top` bounds the highest non-empty heap.
  // (One heap per count is several times faster than a single heap on (count, -vertex).)
  std::vector<std::vector<int32_t>> heaps(1);
  size_t top = 0;
  int32_t next_seed = 0;
  std::vector<int32_t> neighbors;
  while (static_cast<int32_t>(order.size()) < v_count) {
    int32_t v = -1;
    while (top > 0 && v < 0) {
      std::vector<int32_t>& heap = heaps[top];
      while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), std::greater<>());
        const int32_t candidate = heap.back();
        heap.pop_back();
        if (!done[candidate] && static_cast<size_t>(coded_neighbors[candidate]) == top) {
          v = candidate;
          break;
        }
      }
      if (v < 0) --top;
    }
    if (v < 0) {
      while (done[next_seed]) ++next_seed;
      v = next_seed;
    }
    done[v] = 1;
    order.push_back(v);
    adjacency.Neighbors(v, neighbors);
    for (const int32_t n : neighbors) {
      if (done[n]) continue;
      const auto count = static_cast<size_t>(++coded_neighbors[n]);
      if (count >= heaps.size()) heaps.resize(count + 1);
      heaps[count].push_back(n);
      std::push_heap(heaps[count].begin(), heaps[count].end(), std::greater<>());
      top = std::max(top, count);
    }
  }
  return order;
}

LabelPrediction PredictLabel(const TriangleAdjacency& adjacency, std::span<const int32_t> labels,
                             int32_t v, LabelPredictor predictor, int32_t previous_label,
                             std::vector<int64_t>& scratch) {
  const int64_t max_label = adjacency.vertex_count() - 1;
  auto clamped = [max_label](int64_t label) { return std::clamp<int64_t>(label, 0, max_label); };
  const Triangles& triangles = adjacency.triangles();
  LabelPrediction prediction;
  // Decoded neighbours: each appears once per incident triangle, so deduplicate by vertex
  // before taking the median of their labels.
  scratch.clear();
  for (const int32_t f : adjacency.TrianglesOf(v)) {
    for (int k = 0; k < 3; ++k) {
      const int32_t u = triangles(f, k);
      if (u != v && labels[u] >= 0) scratch.push_back(u);
    }
  }
  if (scratch.empty()) {
    prediction.label = clamped(int64_t{previous_label} + 1);
    return prediction;
  }
  std::sort(scratch.begin(), scratch.end());
  scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
  for (int64_t& u : scratch) u = labels[static_cast<size_t>(u)];
  prediction.neighbor_min = static_cast<int32_t>(*std::min_element(scratch.begin(), scratch.end()));
  prediction.neighbor_max = static_cast<int32_t>(*std::max_element(scratch.begin(), scratch.end()));
  prediction.label = clamped(LowerMedian(scratch));
  prediction.kind = PredictionKind::kNeighborMedian;
  if (predictor != LabelPredictor::kParallelogram) return prediction;

  scratch.clear();
  for (const int32_t f : adjacency.TrianglesOf(v)) {
    // The corners after v in f: (v, a, b) in f's orientation.
    const int corner = triangles(f, 0) == v ? 0 : (triangles(f, 1) == v ? 1 : 2);
    const int32_t a = triangles(f, (corner + 1) % 3), b = triangles(f, (corner + 2) % 3);
    if (labels[a] < 0 || labels[b] < 0) continue;
    // The triangles across edge ab are among those of a and among those of b: scan the shorter
    // list, and skip the edge when even that is long, so a crafted stream with huge fans cannot
    // make decoding quadratic.
    const std::span<const int32_t> around_a = adjacency.TrianglesOf(a);
    const std::span<const int32_t> around_b = adjacency.TrianglesOf(b);
    const std::span<const int32_t> around =
        around_a.size() <= around_b.size() ? around_a : around_b;
    if (around.size() > kMaxParallelogramScan) continue;
    for (const int32_t g : around) {
      if (g == f) continue;
      int32_t c = -1;
      int shared = 0;
      for (int k = 0; k < 3; ++k) {
        const int32_t u = triangles(g, k);
        if (u == a || u == b) {
          ++shared;
        } else {
          c = u;
        }
      }
      if (shared != 2 || c < 0 || c == v || labels[c] < 0) continue;
      scratch.push_back(int64_t{labels[a]} + labels[b] - labels[c]);
    }
  }
  if (!scratch.empty()) {
    prediction.label = clamped(LowerMedian(scratch));
    prediction.kind = PredictionKind::kParallelogram;
  }
  return prediction;
}

int LabelContext(const LabelPrediction& prediction, const UnusedLabels& unused,
                 bool spread_contexts) {
  const int base = static_cast<int>(prediction.kind) * kSpreadBuckets;
  if (!spread_contexts || prediction.kind == PredictionKind::kNoNeighbor) return base;
  const int32_t spread =
      unused.Rank(prediction.neighbor_max) - unused.Rank(prediction.neighbor_min);
  const int spread_bits = static_cast<int>(std::bit_width(static_cast<uint32_t>(spread)));
  return base + std::min(spread_bits / 2, kSpreadBuckets - 1);
}

int LabelModelCount(uint8_t version_minor) {
  return version_minor >= 1 ? kLabelModelCount11 : kLabelModelCount;
}

void KernelCenters(const TriangleAdjacency& adjacency, std::span<const int32_t> labels, int32_t v,
                   std::vector<int32_t>& neighbors, std::vector<int32_t>& out) {
  out.clear();
  adjacency.Neighbors(v, neighbors);
  for (const int32_t u : neighbors) {
    if (labels[u] < 0) continue;
    out.push_back(labels[u]);
    if (out.size() == kMaxKernelCenters) break;
  }
}

LabelKernel::LabelKernel(int32_t radius, int32_t label_count)
    : radius_(radius),
      bins_(static_cast<size_t>(2 * radius + 1), 1),
      total_(static_cast<uint64_t>(2 * radius + 1)),
      weight_(static_cast<size_t>(label_count), 0) {}

void LabelKernel::Build(std::span<const int32_t> centers, std::span<const uint8_t> used) {
  candidates_.clear();
  prefix_.assign(1, 0);
  const auto label_count = static_cast<int32_t>(weight_.size());
  // Every label of every window gains its bin, used or not (a branch-free loop); the windows are
  // then walked once in ascending label order, as merged intervals, to list the unused labels
  // with their weights and clear the scratch. No sort: a vertex of the Vlasic meshes has up to 16
  // windows of 513 labels (radius 256), and sorting their candidates took most of the decoder's
  // connectivity time.
  sorted_centers_.assign(centers.begin(), centers.end());
  for (const int32_t center : centers) {
    const int32_t first = std::max(center - radius_, 0);
    const int32_t last = std::min(center + radius_, label_count - 1);
    const uint64_t* bins = bins_.data() + (first - center + radius_);
    uint64_t* weights = weight_.data() + first;
    for (int32_t k = 0; k <= last - first; ++k) weights[k] += bins[k];
  }
  std::sort(sorted_centers_.begin(), sorted_centers_.end());
  int32_t next = 0;  // labels below `next` have been walked
  for (const int32_t center : sorted_centers_) {
    const int32_t first = std::max({center - radius_, 0, next});
    const int32_t last = std::min(center + radius_, label_count - 1);
    for (int32_t label = first; label <= last; ++label) {
      uint64_t& weight = weight_[static_cast<size_t>(label)];
      if (!used[static_cast<size_t>(label)]) {
        candidates_.push_back(label);
        prefix_.push_back(prefix_.back() + weight);
      }
      weight = 0;
    }
    next = std::max(next, last + 1);
  }
}

int32_t LabelKernel::Find(int32_t label) const {
  const auto it = std::lower_bound(candidates_.begin(), candidates_.end(), label);
  if (it == candidates_.end() || *it != label) return -1;
  return static_cast<int32_t>(it - candidates_.begin());
}

uint32_t LabelKernel::SplitP0(int32_t lo, int32_t hi) const {
  const int32_t mid = lo + (hi - lo) / 2;
  const uint64_t left = prefix_[static_cast<size_t>(mid)] - prefix_[static_cast<size_t>(lo)];
  const uint64_t all = prefix_[static_cast<size_t>(hi)] - prefix_[static_cast<size_t>(lo)];
  return static_cast<uint32_t>(std::clamp<uint64_t>((left << 16) / all, 15, 65521));
}

void LabelKernel::Update(std::span<const int32_t> centers, int32_t label) {
  for (const int32_t center : centers) {
    const int64_t difference = int64_t{label} - center;
    if (difference < -radius_ || difference > radius_) continue;
    bins_[static_cast<size_t>(difference + radius_)] += kKernelIncrement;
    total_ += kKernelIncrement;
  }
  if (total_ > kKernelHalvingTotal) {
    total_ = 0;
    for (uint64_t& bin : bins_) {
      bin = (bin + 1) >> 1;
      total_ += bin;
    }
  }
}

UnusedLabels::UnusedLabels(int32_t label_count)
    : tree_(static_cast<size_t>(label_count) + 1, 0), remaining_(label_count) {
  // Linear-time construction of the tree of all-one flags.
  for (int32_t i = 1; i <= label_count; ++i) {
    tree_[i] += 1;
    const int32_t parent = i + (i & -i);
    if (parent <= label_count) tree_[parent] += tree_[i];
  }
  top_bit_ = 1;
  while (top_bit_ * 2 <= label_count) top_bit_ *= 2;
}

int32_t UnusedLabels::Rank(int64_t label) const {
  int32_t sum = 0;
  for (int64_t i = label; i > 0; i -= i & -i) sum += tree_[static_cast<size_t>(i)];
  return sum;
}

int32_t UnusedLabels::Select(int32_t rank) const {
  // Fenwick descent to the largest 1-based position p whose prefix count is <= rank: position
  // p + 1 holds the wanted label, which is 0-based label p.
  int32_t position = 0;
  const int32_t n = static_cast<int32_t>(tree_.size()) - 1;
  for (int32_t step = top_bit_; step > 0; step >>= 1) {
    const int32_t next = position + step;
    if (next <= n && tree_[next] <= rank) {
      position = next;
      rank -= tree_[next];
    }
  }
  return position;
}

void UnusedLabels::Remove(int32_t label) {
  const int32_t n = static_cast<int32_t>(tree_.size()) - 1;
  for (int32_t i = label + 1; i <= n; i += i & -i) --tree_[i];
  --remaining_;
}

StatusOr<Triangles> DecodeDracoTriangles(std::span<const uint8_t> draco_buffer,
                                         uint32_t vertex_count, uint32_t triangle_count,
                                         std::vector<int32_t>* point_values) {
  // Check what Draco would otherwise trust: the header and the counts it allocates from.
  ByteReader reader(draco_buffer);
  for (size_t i = 0; i < kDracoHeader.size(); ++i) {
    uint8_t byte;
    DMC_RETURN_IF_ERROR(reader.GetU8(&byte, "Draco header"));
    if (byte != kDracoHeader[i]) {
      return CorruptStreamError("Draco header byte " + ToString(static_cast<int64_t>(i)) + " is " +
                                ToString(byte) + ", expected " + ToString(kDracoHeader[i]) +
                                " (edgebreaker mesh, bitstream 2.2, no metadata)");
    }
  }
  uint8_t traversal;
  DMC_RETURN_IF_ERROR(reader.GetU8(&traversal, "Draco edgebreaker traversal"));
  if (traversal != kDracoStandardTraversal && traversal != kDracoValenceTraversal) {
    return CorruptStreamError("Draco edgebreaker traversal " + ToString(traversal) +
                              " is not standard (0) or valence (2)");
  }
  uint64_t count;
  DMC_RETURN_IF_ERROR(reader.GetVarU(&count, "Draco vertex count"));
  if (count != vertex_count) {
    return CorruptStreamError("Draco buffer has " + ToString(static_cast<int64_t>(count)) +
                              " vertices, the sequence header " + ToString(vertex_count));
  }
  DMC_RETURN_IF_ERROR(reader.GetVarU(&count, "Draco face count"));
  if (count != triangle_count) {
    return CorruptStreamError("Draco buffer has " + ToString(static_cast<int64_t>(count)) +
                              " triangles, the sequence header " + ToString(triangle_count));
  }

  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(draco_buffer.data()), draco_buffer.size());
  draco::Decoder decoder;
  draco::StatusOr<std::unique_ptr<draco::Mesh>> decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) {
    return CorruptStreamError("Draco cannot decode the connectivity: " +
                              decoded.status().error_msg_string());
  }
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (mesh == nullptr) return CorruptStreamError("Draco returned no mesh");
  if (mesh->num_points() != vertex_count || mesh->num_faces() != triangle_count) {
    return CorruptStreamError("Draco decoded " + ToString(mesh->num_points()) + " vertices and " +
                              ToString(mesh->num_faces()) + " triangles, the sequence header has " +
                              ToString(vertex_count) + " and " + ToString(triangle_count));
  }
  Triangles triangles(triangle_count, 3);
  for (uint32_t f = 0; f < triangle_count; ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const uint32_t point = face[k].value();
      if (point >= vertex_count) {
        return CorruptStreamError("Draco triangle " + ToString(f) + " has vertex " +
                                  ToString(point) + " outside [0, " + ToString(vertex_count) + ")");
      }
      triangles(f, k) = static_cast<int32_t>(point);
    }
  }
  if (point_values != nullptr) {
    const draco::PointAttribute* position =
        mesh->GetNamedAttribute(draco::GeometryAttribute::POSITION);
    if (position == nullptr) return CorruptStreamError("Draco mesh has no position attribute");
    point_values->resize(vertex_count);
    for (uint32_t p = 0; p < vertex_count; ++p) {
      (*point_values)[p] =
          static_cast<int32_t>(position->mapped_index(draco::PointIndex(p)).value());
    }
  }
  return triangles;
}

}  // namespace connectivity

StatusOr<Triangles> DecodeConnectivity(std::span<const uint8_t> payload, uint32_t vertex_count,
                                       uint32_t triangle_count, uint8_t version_minor) {
  if (payload.empty()) return TruncatedStreamError("connectivity payload is empty");
  switch (payload[0]) {
    case static_cast<uint8_t>(ConnectivityCoding::kIndexed):
      return connectivity::DecodeIndexed(payload, vertex_count, triangle_count);
    case static_cast<uint8_t>(ConnectivityCoding::kDracoWithVertexOrder):
      return connectivity::DecodeDracoWithVertexOrder(payload, vertex_count, triangle_count,
                                                      version_minor);
    case static_cast<uint8_t>(ConnectivityCoding::kDracoReordered):
      return connectivity::DecodeDracoReordered(payload, vertex_count, triangle_count);
    default:
      return UnsupportedError("connectivity method " + std::to_string(payload[0]) + " is unknown");
  }
}

}  // namespace dmc

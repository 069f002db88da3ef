#include "bitstream/syntax.h"

#include <xxhash.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <set>

#include "dmc/operator_traits.h"

namespace dmc::format {

// GCC/Clang's 128-bit integer; __extension__ keeps -Wpedantic quiet about it.
__extension__ using Int128 = __int128;

uint32_t ChunkChecksum(uint8_t chunk_type, std::span<const uint8_t> payload,
                       uint8_t version_minor) {
  return XXH32(payload.data(), payload.size(), chunk_type + 256u * version_minor);
}

std::vector<int32_t> BreadthFirstOrder(const MeshTopology& topology) {
  const int v_count = topology.vertex_count;
  std::vector<int32_t> order;
  order.reserve(v_count);
  std::vector<uint8_t> visited(v_count, 0);
  for (int seed = 0; seed < v_count; ++seed) {
    if (visited[seed]) continue;
    visited[seed] = 1;
    size_t head = order.size();
    order.push_back(seed);
    while (head < order.size()) {
      const int v = order[head++];
      for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
        const int n = topology.ring_neighbors[k];
        if (!visited[n]) {
          visited[n] = 1;
          order.push_back(n);
        }
      }
    }
  }
  return order;
}

std::vector<WeightVisit> BuildWeightSchedule(const MeshTopology& topology) {
  const int v_count = topology.vertex_count;
  std::vector<int32_t> known_count(v_count, 0);
  std::vector<uint8_t> edge_known(topology.edge_count(), 0);
  std::vector<uint8_t> visited(v_count, 0);
  // Ordered by (-known, vertex): the first element is the next vertex to visit.
  // Isolated vertices have no edge to code and change no other vertex's count: leaving them out
  // keeps the schedule and makes its cost independent of them.
  std::set<std::pair<int32_t, int32_t>> queue;
  for (int v = 0; v < v_count; ++v) {
    if (topology.ring_offsets[v + 1] > topology.ring_offsets[v]) queue.insert({0, v});
  }
  std::vector<WeightVisit> schedule;
  while (!queue.empty()) {
    const int v = queue.begin()->second;
    queue.erase(queue.begin());
    visited[v] = 1;
    WeightVisit visit{v, {}};
    for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
      const int e = topology.ring_edges[k];
      if (edge_known[e]) continue;
      visit.unknown_edges.push_back(e);
      edge_known[e] = 1;
      const int n = topology.ring_neighbors[k];
      if (!visited[n]) {
        queue.erase({-known_count[n], n});
        ++known_count[n];
        queue.insert({-known_count[n], n});
      }
    }
    if (!visit.unknown_edges.empty()) schedule.push_back(std::move(visit));
  }
  return schedule;
}

bool IsCodecOperator(uint8_t operator_id) {
  const OperatorTraits* traits = FindOperatorTraits(static_cast<OperatorId>(operator_id));
  return traits != nullptr && traits->codec();
}

bool IsGeometricOperator(uint8_t operator_id) {
  const OperatorTraits* traits = FindOperatorTraits(static_cast<OperatorId>(operator_id));
  return traits != nullptr && traits->geometric();
}

int64_t ReferenceWeight(const MeshTopology& topology, int edge) {
  const int64_t di = topology.degree(topology.edges[edge][0]);
  const int64_t dj = topology.degree(topology.edges[edge][1]);
  return ((di + dj) << 20) / (2 * di * dj);
}

int64_t PredictWeight(WeightPrediction mode, int64_t remaining, const MeshTopology& topology,
                      std::span<const int32_t> unknown_edges) {
  const auto n = static_cast<int64_t>(unknown_edges.size());
  if (mode == WeightPrediction::kUniform) return RoundDiv(remaining, n);
  // Exact in 128 bits: |remaining| < 2^47 and reference weights < 2^21, so no product overflows
  // however large the fan (the spec defines the prediction in exact integers).
  Int128 total = 0;
  for (int32_t e : unknown_edges) total += ReferenceWeight(topology, e);
  // Every reference weight rounds to 0 only around vertices of degree above 2^20 (a crafted
  // stream): the prediction is then the uniform one, not a division by zero (§9.4).
  if (total == 0) return RoundDiv(remaining, n);
  const Int128 numerator =
      static_cast<Int128>(remaining) * ReferenceWeight(topology, unknown_edges[0]);
  const Int128 a = 2 * numerator + total, b = 2 * total;
  Int128 q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;  // floor division
  return static_cast<int64_t>(q);
}

int64_t RoundDiv(int64_t numerator, int64_t denominator) {
  const int64_t a = 2 * numerator + denominator;
  const int64_t b = 2 * denominator;
  int64_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;  // floor division
  return q;
}

int ResidualColumnGroup(int column) {
  if (column < 16) return column;
  return std::min(16 + (column - 16) / 16, kResidualColumnGroups - 1);
}

EarlierNeighbours ListEarlierNeighbours(const MeshTopology& topology,
                                        std::span<const int32_t> vertex_order) {
  const auto v_count = static_cast<int>(vertex_order.size());
  std::vector<int32_t> position(vertex_order.size());
  for (int i = 0; i < v_count; ++i) position[vertex_order[i]] = i;
  EarlierNeighbours earlier;
  earlier.offsets.assign(vertex_order.size() + 1, 0);
  earlier.positions.reserve(topology.ring_neighbors.size() / 2 + 1);
  for (int i = 0; i < v_count; ++i) {
    const int v = vertex_order[i];
    for (int r = topology.ring_offsets[v]; r < topology.ring_offsets[v + 1]; ++r) {
      const int p = position[topology.ring_neighbors[r]];
      if (p < i) earlier.positions.push_back(p);
    }
    earlier.offsets[i + 1] = static_cast<int32_t>(earlier.positions.size());
  }
  return earlier;
}

int ResidualActivityBucket(int64_t abs_sum, int coded_neighbours) {
  if (coded_neighbours == 0 || abs_sum == 0) return 0;
  const int64_t mean = (2 * abs_sum + coded_neighbours) / (2 * coded_neighbours);
  return std::min<int>(kResidualActivityBuckets - 1,
                       std::bit_width(static_cast<uint64_t>(mean)) + 1);
}

int ResidualContext11(int column, int64_t earlier_sum, int earlier_count, uint32_t fast,
                      uint32_t slow) {
  int64_t numerator = 0;
  int64_t weights = 0;
  if (earlier_count > 0) {
    numerator += 32 * earlier_sum / earlier_count;
    weights += 2;
  }
  if (column >= 1) {
    numerator += int64_t{fast} + slow;
    weights += 2;
  }
  const int64_t activity = weights == 0 ? 0 : numerator / weights;
  const int octave =
      std::min<int>(kResidualActivityOctaves - 1, std::bit_width(static_cast<uint64_t>(activity)));
  return 2 * octave + (earlier_count > 0 && earlier_sum == 0 ? 1 : 0);
}

ResidualContextSelector::ResidualContextSelector(const MeshTopology& topology,
                                                 std::span<const int32_t> vertex_order,
                                                 uint8_t version_minor)
    : minor_(version_minor),
      earlier_(ListEarlierNeighbours(topology, vertex_order)),
      current_(vertex_order.size(), 0),
      contexts_(std::make_unique<ResidualContexts>()) {
  if (minor_ >= 1) {
    fast_.assign(vertex_order.size(), 0);
    slow_.assign(vertex_order.size(), 0);
  }
}

int ResidualContextSelector::Context11(int column, int i) const {
  int64_t sum = 0;
  for (int32_t e = earlier_.offsets[i]; e < earlier_.offsets[i + 1]; ++e) {
    sum += std::min(current_[earlier_.positions[e]], kResidualActivityClamp);
  }
  return ResidualContext11(column, sum, earlier_.offsets[i + 1] - earlier_.offsets[i], fast_[i],
                           slow_[i]);
}

ReferenceFramePredictor::ReferenceFramePredictor(const MeshTopology& topology)
    : topology_(topology),
      order_(BreadthFirstOrder(topology)),
      coded_(topology.vertex_count, 0),
      values_(topology.vertex_count) {}

bool ReferenceFramePredictor::Predict(int v, std::array<int64_t, 3>* prediction) const {
  std::array<int64_t, 3> sum = {0, 0, 0};
  int count = 0;
  for (int k = topology_.ring_offsets[v]; k < topology_.ring_offsets[v + 1]; ++k) {
    const int n = topology_.ring_neighbors[k];
    if (!coded_[n]) continue;
    for (int axis = 0; axis < 3; ++axis) sum[axis] += values_[n][axis];
    ++count;
  }
  for (int axis = 0; axis < 3; ++axis) {
    (*prediction)[axis] = count > 0 ? RoundDiv(sum[axis], count) : previous_[axis];
  }
  return count > 0;
}

void ReferenceFramePredictor::Record(int v, const std::array<int64_t, 3>& values) {
  values_[v] = values;
  coded_[v] = 1;
  previous_ = values;
}

double StepFactor(int exponent) {
  // 2^(j/4) rounded to the nearest double, j = 0..3 (spec §8.5.1).
  static constexpr double kQuarterPowers[kStepExponentsPerOctave] = {
      0x1.0000000000000p+0, 0x1.306fe0a31b715p+0, 0x1.6a09e667f3bcdp+0, 0x1.ae89f995ad3adp+0};
  const int octave = exponent >= 0
                         ? exponent / kStepExponentsPerOctave
                         : -((-exponent + kStepExponentsPerOctave - 1) / kStepExponentsPerOctave);
  return std::ldexp(kQuarterPowers[exponent - octave * kStepExponentsPerOctave], octave);
}

std::vector<int32_t> AnchorRegions(const MeshTopology& topology, std::span<const int32_t> anchors) {
  const int v_count = topology.vertex_count;
  std::vector<int32_t> owner(v_count, -1);
  std::vector<uint8_t> settled(v_count, 0);  // reached at an earlier level
  std::vector<int32_t> frontier, next;
  for (size_t a = 0; a < anchors.size(); ++a) {
    const int32_t v = anchors[a];
    if (v < 0 || v >= v_count || owner[v] >= 0) continue;
    owner[v] = static_cast<int32_t>(a);
    settled[v] = 1;
    frontier.push_back(v);
  }
  // Level by level, so that a vertex reached from several anchors at the same distance takes
  // the first listed whatever the order of the rings.
  while (!frontier.empty()) {
    next.clear();
    for (const int32_t v : frontier) {
      for (int k = topology.ring_offsets[v]; k < topology.ring_offsets[v + 1]; ++k) {
        const int32_t u = topology.ring_neighbors[k];
        if (settled[u]) continue;
        if (owner[u] < 0) {
          owner[u] = owner[v];
          next.push_back(u);
        } else {
          owner[u] = std::min(owner[u], owner[v]);
        }
      }
    }
    for (const int32_t u : next) settled[u] = 1;
    frontier.swap(next);
  }
  return owner;
}

std::vector<double> VertexStepFactors(const MeshTopology& topology,
                                      std::span<const int32_t> anchors,
                                      std::span<const int8_t> exponents) {
  if (std::all_of(exponents.begin(), exponents.end(), [](int8_t e) { return e == 0; })) return {};
  const std::vector<int32_t> owner = AnchorRegions(topology, anchors);
  std::vector<double> factor(owner.size(), 1.0);
  for (size_t v = 0; v < owner.size(); ++v) {
    if (owner[v] >= 0 && static_cast<size_t>(owner[v]) < exponents.size()) {
      factor[v] = StepFactor(exponents[owner[v]]);
    }
  }
  return factor;
}

}  // namespace dmc::format

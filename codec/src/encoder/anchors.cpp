#include "encoder/anchors.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace dmc {
namespace {

constexpr double kAnchorFraction = 0.01;
constexpr double kLongSegmentAnchorFraction = 0.02;
constexpr int kMaxAutomaticAnchors = 1000;

}  // namespace

int RequestedAnchorCount(const EncoderOptions& options, int vertex_count, int frame_count) {
  if (options.anchors >= 0) return options.anchors;
  const double fraction =
      frame_count >= kLongSegmentFrames ? kLongSegmentAnchorFraction : kAnchorFraction;
  return std::clamp(static_cast<int>(std::lround(fraction * vertex_count)), 1,
                    kMaxAutomaticAnchors);
}

// Each round scans the vertices in fixed blocks in parallel; the farthest vertex (lowest index on
// ties) does not depend on the thread count.
std::vector<int32_t> ChooseAnchors(const Eigen::MatrixXd& mean_shape, const MeshTopology& topology,
                                   int count) {
  const int v_count = topology.vertex_count;
  count = std::clamp(count, 1, v_count);
  std::vector<double> distance(v_count, std::numeric_limits<double>::infinity());
  std::vector<uint8_t> chosen(v_count, 0);
  std::vector<int32_t> anchors;
  constexpr int kBlock = 8192;
  const int blocks = (v_count + kBlock - 1) / kBlock;
  std::vector<std::pair<double, int>> block_best(blocks);
  int next = 0;
  for (int a = 0; a < count; ++a) {
    anchors.push_back(next);
    chosen[next] = 1;
    const Eigen::RowVector3d p = mean_shape.row(next);
    tbb::parallel_for(0, blocks, [&](int block) {
      std::pair<double, int> best{-1.0, -1};
      const int end = std::min(v_count, (block + 1) * kBlock);
      for (int v = block * kBlock; v < end; ++v) {
        distance[v] = std::min(distance[v], (mean_shape.row(v) - p).squaredNorm());
        if (!chosen[v] && distance[v] > best.first) best = {distance[v], v};
      }
      block_best[block] = best;
    });
    std::pair<double, int> farthest{-1.0, -1};
    for (const auto& best : block_best) {
      if (best.first > farthest.first) farthest = best;
    }
    if (farthest.second < 0) break;
    next = farthest.second;
  }
  std::vector<uint8_t> anchored(topology.component_count, 0);
  for (int32_t a : anchors) anchored[topology.component_of_vertex[a]] = 1;
  for (int v = 0; v < v_count; ++v) {
    const int c = topology.component_of_vertex[v];
    if (!anchored[c]) {
      anchored[c] = 1;
      anchors.push_back(v);
    }
  }
  std::sort(anchors.begin(), anchors.end());
  return anchors;
}

}  // namespace dmc

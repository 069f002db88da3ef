#include "tvm/kd_tree.h"

#include <algorithm>
#include <limits>
#include <numeric>

namespace dmc::tvm_internal {

namespace {

// Leaves hold at most this many points: below it a linear scan beats descending further.
constexpr int kLeafSize = 8;

}  // namespace

KdTree::KdTree(const FramePositionsD& points) : points_(points) {
  order_.resize(static_cast<size_t>(points.rows()));
  std::iota(order_.begin(), order_.end(), 0);
  if (!order_.empty()) {
    nodes_.reserve(2 * order_.size() / kLeafSize + 2);
    Build(0, static_cast<int>(order_.size()));
  }
}

int KdTree::Build(int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(Node{begin, end});
  if (end - begin <= kLeafSize) return index;

  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (int i = begin; i < end; ++i) {
    const Eigen::Vector3d p = points_.row(order_[i]).transpose();
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  int axis = 0;
  (high - low).maxCoeff(&axis);
  if (high[axis] <= low[axis]) return index;  // all points coincide: keep one leaf

  const int middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int32_t a, int32_t b) { return points_(a, axis) < points_(b, axis); });
  const double split = points_(order_[middle], axis);
  const int left = Build(begin, middle);
  const int right = Build(middle, end);
  Node& node = nodes_[static_cast<size_t>(index)];
  node.axis = axis;
  node.split = split;
  node.left = left;
  node.right = right;
  return index;
}

int KdTree::Nearest(const Eigen::Vector3d& query) const {
  const auto nearest = KNearest(query, 1);
  return nearest.empty() ? -1 : nearest.front().second;
}

std::vector<std::pair<double, int32_t>> KdTree::KNearest(const Eigen::Vector3d& query,
                                                         int k) const {
  std::vector<std::pair<double, int32_t>> best;  // sorted ascending, at most k entries
  if (nodes_.empty() || k <= 0) return best;
  best.reserve(static_cast<size_t>(k) + 1);
  auto worst = [&] {
    return static_cast<int>(best.size()) < k ? std::numeric_limits<double>::infinity()
                                             : best.back().first;
  };
  // Explicit stack of (node, squared distance lower bound to the node's half-space).
  std::vector<std::pair<int, double>> stack{{0, 0.0}};
  while (!stack.empty()) {
    const auto [index, bound] = stack.back();
    stack.pop_back();
    if (bound > worst()) continue;
    const Node& node = nodes_[static_cast<size_t>(index)];
    if (node.axis < 0) {
      for (int i = node.begin; i < node.end; ++i) {
        const int32_t point = order_[static_cast<size_t>(i)];
        const double d2 = (points_.row(point).transpose() - query).squaredNorm();
        const std::pair<double, int32_t> entry{d2, point};
        if (static_cast<int>(best.size()) == k && !(entry < best.back())) continue;
        best.insert(std::upper_bound(best.begin(), best.end(), entry), entry);
        if (static_cast<int>(best.size()) > k) best.pop_back();
      }
      continue;
    }
    const double delta = query[node.axis] - node.split;
    const int near = delta < 0.0 ? node.left : node.right;
    const int far = delta < 0.0 ? node.right : node.left;
    // Far side first on the stack so the near side is searched first.
    stack.emplace_back(far, std::max(bound, delta * delta));
    stack.emplace_back(near, bound);
  }
  return best;
}

void KdTree::WithinRadius(const Eigen::Vector3d& query, double radius_squared,
                          std::vector<int32_t>& out) const {
  if (nodes_.empty()) return;
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const Node& node = nodes_[static_cast<size_t>(stack.back())];
    stack.pop_back();
    if (node.axis < 0) {
      for (int i = node.begin; i < node.end; ++i) {
        const int32_t point = order_[static_cast<size_t>(i)];
        if ((points_.row(point).transpose() - query).squaredNorm() <= radius_squared) {
          out.push_back(point);
        }
      }
      continue;
    }
    const double delta = query[node.axis] - node.split;
    // Points equal to the split value may lie on either side of the median partition.
    if (delta <= 0.0 || delta * delta <= radius_squared) stack.push_back(node.left);
    if (delta >= 0.0 || delta * delta <= radius_squared) stack.push_back(node.right);
  }
}

}  // namespace dmc::tvm_internal

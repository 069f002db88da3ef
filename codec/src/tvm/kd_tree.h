// Internal: a static 3-D kd-tree over a fixed point set (the centres of one frame), for nearest,
// k-nearest and radius queries. Built once in O(n log n) by median splits on the widest axis;
// queries are exact. The tree stores a permutation of indices, not copies of the points' identity,
// and reports original indices.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "dmc/sequence.h"

namespace dmc::tvm_internal {

class KdTree {
 public:
  KdTree() = default;
  explicit KdTree(const FramePositionsD& points);

  int size() const { return static_cast<int>(order_.size()); }

  // Index of the nearest point (ties: lower index); -1 on an empty tree.
  int Nearest(const Eigen::Vector3d& query) const;
  // The min(k, size) nearest points as (squared distance, index), ascending (ties: lower index).
  std::vector<std::pair<double, int32_t>> KNearest(const Eigen::Vector3d& query, int k) const;
  // Every point with squared distance <= radius_squared, in no particular order (appended).
  void WithinRadius(const Eigen::Vector3d& query, double radius_squared,
                    std::vector<int32_t>& out) const;

 private:
  struct Node {
    int32_t begin, end;  // range of order_; a leaf when `axis` < 0
    int32_t left = -1, right = -1;
    int axis = -1;
    double split = 0.0;
  };
  int Build(int begin, int end);

  FramePositionsD points_;
  std::vector<int32_t> order_;
  std::vector<Node> nodes_;
};

}  // namespace dmc::tvm_internal

// Exact diameter of a point set: lower bound, then branch-and-bound over pairs of kd-tree nodes.
//
// Exactness argument. For points p in box P and q in box Q, on each axis
// |p_k − q_k| <= max(P.hi_k − Q.lo_k, Q.hi_k − P.lo_k), and this still holds after rounding
// because floating-point subtraction is monotone. Squaring non-negative values and adding are
// monotone too, so the box bound computed with the same operation sequence as SquaredDistance is
// never below any computed pair distance inside the boxes. A node pair is dropped only when its
// bound is <= the best squared distance found so far, so the maximum is never lost, and the
// value returned is exactly the brute-force maximum of SquaredDistance (then one sqrt).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "dmc/metrics.h"

namespace dmc {
namespace {

using Point = std::array<double, 3>;

// The one distance expression used everywhere in this file (see the exactness argument above).
inline double SquaredDistance(const Point& a, const Point& b) {
  const double dx = a[0] - b[0];
  const double dy = a[1] - b[1];
  const double dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

struct KdNode {
  Point lo, hi;               // bounding box of the node's points
  int begin = 0, end = 0;     // the node's points are points[begin, end)
  int left = -1, right = -1;  // children; -1 for a leaf
  bool is_leaf() const { return left < 0; }
};

// Leaves small enough that their all-pairs loop is cheap, large enough to keep the tree shallow.
constexpr int kLeafSize = 8;

class KdTree {
 public:
  explicit KdTree(std::vector<Point> points) : points_(std::move(points)) {
    nodes_.reserve(2 * points_.size() / kLeafSize + 2);
    Build(0, static_cast<int>(points_.size()));
  }
  const std::vector<Point>& points() const { return points_; }
  const std::vector<KdNode>& nodes() const { return nodes_; }

 private:
  // Builds the subtree over points_[begin, end) and returns its node index. Splits at the median
  // of the box's longest axis, so the depth is O(log n).
  int Build(int begin, int end) {
    const int index = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    KdNode node;
    node.begin = begin;
    node.end = end;
    node.lo = node.hi = points_[begin];
    for (int i = begin + 1; i < end; ++i) {
      for (int k = 0; k < 3; ++k) {
        node.lo[k] = std::min(node.lo[k], points_[i][k]);
        node.hi[k] = std::max(node.hi[k], points_[i][k]);
      }
    }
    if (end - begin > kLeafSize) {
      int axis = 0;
      for (int k = 1; k < 3; ++k) {
        if (node.hi[k] - node.lo[k] > node.hi[axis] - node.lo[axis]) axis = k;
      }
      const int middle = begin + (end - begin) / 2;
      std::nth_element(points_.begin() + begin, points_.begin() + middle, points_.begin() + end,
                       [axis](const Point& a, const Point& b) { return a[axis] < b[axis]; });
      node.left = Build(begin, middle);
      node.right = Build(middle, end);
    }
    nodes_[index] = node;
    return index;
  }

  std::vector<Point> points_;
  std::vector<KdNode> nodes_;
};

// Upper bound on SquaredDistance(p, q) for p in `a`, q in `b` (see the exactness argument).
inline double BoxMaxSquaredDistance(const KdNode& a, const KdNode& b) {
  const double gx = std::max(a.hi[0] - b.lo[0], b.hi[0] - a.lo[0]);
  const double gy = std::max(a.hi[1] - b.lo[1], b.hi[1] - a.lo[1]);
  const double gz = std::max(a.hi[2] - b.lo[2], b.hi[2] - a.lo[2]);
  return gx * gx + gy * gy + gz * gz;
}

// A cheap, usually tight lower bound: the farthest pair among the extreme points along a few
// directions, then farthest-point steps from its endpoints while they improve it. A good start
// lets the branch-and-bound drop most node pairs on first sight.
double InitialLowerBound(const std::vector<Point>& points) {
  static constexpr std::array<std::array<double, 3>, 7> kDirections = {
      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}}};
  std::vector<int> extremes;
  for (const auto& direction : kDirections) {
    int arg_min = 0, arg_max = 0;
    double min_projection = std::numeric_limits<double>::infinity();
    double max_projection = -min_projection;
    for (int i = 0; i < static_cast<int>(points.size()); ++i) {
      const double projection =
          direction[0] * points[i][0] + direction[1] * points[i][1] + direction[2] * points[i][2];
      if (projection < min_projection) {
        min_projection = projection;
        arg_min = i;
      }
      if (projection > max_projection) {
        max_projection = projection;
        arg_max = i;
      }
    }
    extremes.push_back(arg_min);
    extremes.push_back(arg_max);
  }
  double best = 0.0;
  int best_endpoint = 0;
  for (size_t i = 0; i < extremes.size(); ++i) {
    for (size_t j = i + 1; j < extremes.size(); ++j) {
      const double d = SquaredDistance(points[extremes[i]], points[extremes[j]]);
      if (d > best) {
        best = d;
        best_endpoint = extremes[i];
      }
    }
  }
  // Farthest-point (double normal) iteration: each step can only increase the distance, and it
  // stops within a few steps in practice; the cap keeps adversarial inputs linear.
  for (int step = 0; step < 4; ++step) {
    int farthest = best_endpoint;
    double farthest_distance = -1.0;
    for (int i = 0; i < static_cast<int>(points.size()); ++i) {
      const double d = SquaredDistance(points[best_endpoint], points[i]);
      if (d > farthest_distance) {
        farthest_distance = d;
        farthest = i;
      }
    }
    if (farthest_distance <= best) break;
    best = farthest_distance;
    best_endpoint = farthest;
  }
  return best;
}

}  // namespace

double PointSetDiameter(const Eigen::Ref<const FramePositions>& points) {
  const int n = static_cast<int>(points.rows());
  if (n < 2) return 0.0;
  std::vector<Point> converted(n);
  for (int i = 0; i < n; ++i) {
    converted[i] = {static_cast<double>(points(i, 0)), static_cast<double>(points(i, 1)),
                    static_cast<double>(points(i, 2))};
  }
  double best = InitialLowerBound(converted);
  const KdTree tree(std::move(converted));
  const std::vector<Point>& pts = tree.points();
  const std::vector<KdNode>& nodes = tree.nodes();

  // Depth-first over node pairs. A pair (a, a) expands to its children's three pairs and a pair of
  // distinct nodes to two pairs, so each unordered pair of points is visited at most once. The
  // more promising child pair is pushed last to be explored first.
  std::vector<std::pair<int, int>> stack = {{0, 0}};
  auto push_both = [&](std::pair<int, int> first, std::pair<int, int> second) {
    double bound_first = BoxMaxSquaredDistance(nodes[first.first], nodes[first.second]);
    double bound_second = BoxMaxSquaredDistance(nodes[second.first], nodes[second.second]);
    if (bound_first > bound_second) {
      std::swap(first, second);
      std::swap(bound_first, bound_second);
    }
    if (bound_first > best) stack.push_back(first);
    if (bound_second > best) stack.push_back(second);  // on top: explored first
  };
  while (!stack.empty()) {
    const auto [ia, ib] = stack.back();
    stack.pop_back();
    const KdNode& a = nodes[ia];
    const KdNode& b = nodes[ib];
    if (BoxMaxSquaredDistance(a, b) <= best) continue;
    if (a.is_leaf() && b.is_leaf()) {
      for (int i = a.begin; i < a.end; ++i) {
        for (int j = (ia == ib ? i + 1 : b.begin); j < b.end; ++j) {
          best = std::max(best, SquaredDistance(pts[i], pts[j]));
        }
      }
      continue;
    }
    if (ia == ib) {
      // A node against itself: its two children against themselves and each other.
      stack.push_back({a.left, a.left});
      stack.push_back({a.right, a.right});
      stack.push_back({a.left, a.right});  // usually the farthest pair: explored first
      continue;
    }
    // Split the node with the larger box (a leaf is never split).
    const bool split_a =
        b.is_leaf() || (!a.is_leaf() && SquaredDistance(a.lo, a.hi) >= SquaredDistance(b.lo, b.hi));
    if (split_a) {
      push_both({a.left, ib}, {a.right, ib});
    } else {
      push_both({ia, b.left}, {ia, b.right});
    }
  }
  return std::sqrt(best);
}

}  // namespace dmc

// Exact diameter of a point set: a lower bound, then branch-and-bound over pairs of kd-tree nodes.
//
// Every node carries two bounding volumes: its axis-aligned box, and an oriented box in the
// principal frame of its points. Points on a curved surface make thin oriented boxes (their
// thickness is the surface's bulge, not the patch size) while axis-aligned boxes of patches that
// face a diagonal direction are fat; with axis-aligned boxes alone, n points spread on a sphere
// cost O(n^1.5) pair tests, with both the search stays close to linear.
//
// Exactness argument.
//  - Axis-aligned boxes: for p in box P and q in box Q, on each axis
//    |p_k − q_k| <= max(P.hi_k − Q.lo_k, Q.hi_k − P.lo_k), and this still holds after rounding
//    because floating-point subtraction is monotone. Squaring non-negative values and adding are
//    monotone too, so the bound computed with the same operation sequence as SquaredDistance is
//    never below any computed pair distance inside the boxes.
//  - Oriented boxes: projections onto computed axes carry rounding errors of a few ulps of the
//    largest coordinate magnitude M, and the axes are orthonormal only to a few ulps. The bound
//    therefore widens every interval by a slack of 1e-12·M (far above those errors) and scales
//    the result by (1 + 1e-12) (far above the relative rounding of SquaredDistance and of the
//    bound itself), so it too is never below a computed pair distance inside the boxes.
//  - A node pair is dropped only when a bound is <= the best squared distance found so far, so
//    the maximum is never lost, and the value returned is exactly the brute-force maximum of
//    SquaredDistance (then one sqrt).
#include <Eigen/Eigenvalues>
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

inline double Dot(const Point& a, const Point& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

struct KdNode {
  Point lo, hi;               // axis-aligned bounding box of the node's points
  std::array<Point, 3> axes;  // orthonormal frame (principal axes of the points)
  Point axis_lo, axis_hi;     // extent of the points' projections onto `axes`
  int begin = 0, end = 0;     // the node's points are points[begin, end)
  int left = -1, right = -1;  // children, -1 until the node is split
};

// Leaves small enough that their all-pairs loop is cheap, large enough to keep the tree shallow.
constexpr int kLeafSize = 8;

// The principal axes of `points[begin, end)` made exactly orthonormal by Gram–Schmidt, or the
// coordinate axes when they are not well defined (coincident points).
std::array<Point, 3> PrincipalFrame(const std::vector<Point>& points, int begin, int end) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i = begin; i < end; ++i)
    mean += Eigen::Vector3d(points[i][0], points[i][1], points[i][2]);
  mean /= static_cast<double>(end - begin);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int i = begin; i < end; ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(points[i][0], points[i][1], points[i][2]) - mean;
    covariance.noalias() += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3d u0 = solver.eigenvectors().col(2).normalized();
  const Eigen::Vector3d e1 = solver.eigenvectors().col(1);
  const Eigen::Vector3d u1 = (e1 - e1.dot(u0) * u0).normalized();
  const Eigen::Vector3d u2 = u0.cross(u1);
  if (!u0.allFinite() || !u1.allFinite() || !u2.allFinite()) {
    return {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  }
  return {{{u0.x(), u0.y(), u0.z()}, {u1.x(), u1.y(), u1.z()}, {u2.x(), u2.y(), u2.z()}}};
}

// A kd-tree built lazily: a node is split (median of its box's longest axis) only when the search
// first needs its children. On typical, elongated shapes the search touches a few hundred nodes,
// so most of the O(n log n) build never happens.
class LazyKdTree {
 public:
  explicit LazyKdTree(std::vector<Point> points) : points_(std::move(points)) {
    nodes_.push_back(MakeNode(0, static_cast<int>(points_.size())));
  }
  const std::vector<Point>& points() const { return points_; }
  // Valid until the next Split (which may reallocate the node array): copy to keep it longer.
  const KdNode& node(int index) const { return nodes_[index]; }
  bool is_leaf(int index) const { return nodes_[index].end - nodes_[index].begin <= kLeafSize; }

  // Splits a non-leaf node if not done yet and returns it with its children set.
  KdNode Split(int index) {
    if (nodes_[index].left < 0) {
      const KdNode node = nodes_[index];
      int axis = 0;
      for (int k = 1; k < 3; ++k) {
        if (node.hi[k] - node.lo[k] > node.hi[axis] - node.lo[axis]) axis = k;
      }
      const int middle = node.begin + (node.end - node.begin) / 2;
      std::nth_element(points_.begin() + node.begin, points_.begin() + middle,
                       points_.begin() + node.end,
                       [axis](const Point& a, const Point& b) { return a[axis] < b[axis]; });
      nodes_[index].left = static_cast<int>(nodes_.size());
      nodes_.push_back(MakeNode(node.begin, middle));
      nodes_[index].right = static_cast<int>(nodes_.size());
      nodes_.push_back(MakeNode(middle, node.end));
    }
    return nodes_[index];
  }

 private:
  KdNode MakeNode(int begin, int end) const {
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
    node.axes = PrincipalFrame(points_, begin, end);
    for (int k = 0; k < 3; ++k) {
      node.axis_lo[k] = std::numeric_limits<double>::infinity();
      node.axis_hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (int i = begin; i < end; ++i) {
      for (int k = 0; k < 3; ++k) {
        const double projection = Dot(points_[i], node.axes[k]);
        node.axis_lo[k] = std::min(node.axis_lo[k], projection);
        node.axis_hi[k] = std::max(node.axis_hi[k], projection);
      }
    }
    return node;
  }

  std::vector<Point> points_;
  std::vector<KdNode> nodes_;
};

// Upper bound on SquaredDistance(p, q) for p in `a`, q in `b` from the axis-aligned boxes.
inline double BoxMaxSquaredDistance(const KdNode& a, const KdNode& b) {
  const double gx = std::max(a.hi[0] - b.lo[0], b.hi[0] - a.lo[0]);
  const double gy = std::max(a.hi[1] - b.lo[1], b.hi[1] - a.lo[1]);
  const double gz = std::max(a.hi[2] - b.lo[2], b.hi[2] - a.lo[2]);
  return gx * gx + gy * gy + gz * gz;
}

// Upper bound on SquaredDistance(p, q) for p in `a`, q in `b` from the oriented boxes: `a`'s
// oriented box, projected onto each axis of `b`'s frame, is an interval (centre ± radius); the
// farthest gap between it and `b`'s extent on that axis bounds |(p − q)·axis|. `slack` absorbs
// the rounding of projections and axes (see the exactness argument).
inline double OrientedMaxSquaredDistance(const KdNode& a, const KdNode& b, double slack) {
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    double centre = 0.0, radius = slack;
    for (int j = 0; j < 3; ++j) {
      const double cosine = Dot(a.axes[j], b.axes[k]);
      centre += 0.5 * (a.axis_lo[j] + a.axis_hi[j]) * cosine;
      radius += 0.5 * (a.axis_hi[j] - a.axis_lo[j]) * std::abs(cosine);
    }
    const double gap =
        std::max(b.axis_hi[k] - (centre - radius), (centre + radius) - b.axis_lo[k]) + slack;
    sum += gap * gap;
  }
  return sum * (1.0 + 1e-12);
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
      const double projection = Dot(direction, points[i]);
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
  double largest_magnitude = 0.0;
  for (int i = 0; i < n; ++i) {
    converted[i] = {static_cast<double>(points(i, 0)), static_cast<double>(points(i, 1)),
                    static_cast<double>(points(i, 2))};
    largest_magnitude = std::max(largest_magnitude, std::sqrt(Dot(converted[i], converted[i])));
  }
  const double slack = 1e-12 * largest_magnitude;
  double best = InitialLowerBound(converted);
  LazyKdTree tree(std::move(converted));
  const std::vector<Point>& pts = tree.points();

  // Both bounds are valid, so the smaller one is; the oriented one is only worth its cost when
  // the axis-aligned one fails to prune.
  auto bound = [&](std::pair<int, int> pair) {
    const KdNode& a = tree.node(pair.first);
    const KdNode& b = tree.node(pair.second);
    const double box_bound = BoxMaxSquaredDistance(a, b);
    if (box_bound <= best) return box_bound;
    return std::min(box_bound, OrientedMaxSquaredDistance(a, b, slack));
  };

  // Depth-first over node pairs. A pair (a, a) expands to its children's three pairs and a pair of
  // distinct nodes to two pairs, so each unordered pair of points is visited at most once. The
  // more promising child pair is pushed last to be explored first.
  std::vector<std::pair<int, int>> stack = {{0, 0}};
  auto push_both = [&](std::pair<int, int> first, std::pair<int, int> second) {
    double bound_first = bound(first);
    double bound_second = bound(second);
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
    if (bound({ia, ib}) <= best) continue;  // `best` may have grown since the push
    const bool a_leaf = tree.is_leaf(ia), b_leaf = tree.is_leaf(ib);
    if (a_leaf && b_leaf) {
      const KdNode& a = tree.node(ia);
      const KdNode& b = tree.node(ib);
      for (int i = a.begin; i < a.end; ++i) {
        for (int j = (ia == ib ? i + 1 : b.begin); j < b.end; ++j) {
          best = std::max(best, SquaredDistance(pts[i], pts[j]));
        }
      }
      continue;
    }
    if (ia == ib) {
      // A node against itself: its two children against themselves and each other.
      const KdNode a = tree.Split(ia);
      stack.push_back({a.left, a.left});
      stack.push_back({a.right, a.right});
      stack.push_back({a.left, a.right});  // usually the farthest pair: explored first
      continue;
    }
    // Split the node with the larger box (a leaf is never split).
    const KdNode& a = tree.node(ia);
    const KdNode& b = tree.node(ib);
    const bool split_a =
        b_leaf || (!a_leaf && SquaredDistance(a.lo, a.hi) >= SquaredDistance(b.lo, b.hi));
    if (split_a) {
      const KdNode split = tree.Split(ia);  // invalidates `a` and `b`
      push_both({split.left, ib}, {split.right, ib});
    } else {
      const KdNode split = tree.Split(ib);
      push_both({ia, split.left}, {ia, split.right});
    }
  }
  return std::sqrt(best);
}

}  // namespace dmc

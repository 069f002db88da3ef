// Measures of the 4D CW complex of a mesh sequence and of its barycentric dual (spacetime.h).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "dmc/spacetime.h"

namespace dmc {
namespace {

Status ValidateInputs(const MeshTopology& topology, const Triangles& triangles,
                      std::span<const FramePositionsD> frames, const SpacetimeOptions& options,
                      std::vector<double>& times) {
  if (frames.size() < 2) {
    return InvalidArgumentError("the spacetime operator needs at least two frames, got " +
                                std::to_string(frames.size()));
  }
  if (!(options.alpha > 0.0) || !std::isfinite(options.alpha)) {
    return InvalidArgumentError("spacetime alpha must be a finite value > 0");
  }
  if (options.quadrature_points < 1 || options.quadrature_points > 64) {
    return InvalidArgumentError("spacetime quadrature_points must lie in [1, 64]");
  }
  for (size_t k = 0; k < frames.size(); ++k) {
    if (frames[k].rows() != topology.vertex_count) {
      return MismatchError("frame " + std::to_string(k) + " has " +
                           std::to_string(frames[k].rows()) + " vertices, the topology " +
                           std::to_string(topology.vertex_count));
    }
  }
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int c = 0; c < 3; ++c) {
      if (triangles(t, c) < 0 || triangles(t, c) >= topology.vertex_count) {
        return InvalidArgumentError("triangle " + std::to_string(t) + " has a vertex outside [0, " +
                                    std::to_string(topology.vertex_count) + ")");
      }
    }
  }
  if (options.frame_times.empty()) {
    times.resize(frames.size());
    for (size_t k = 0; k < frames.size(); ++k) times[k] = static_cast<double>(k);
  } else {
    if (options.frame_times.size() != frames.size()) {
      return InvalidArgumentError("spacetime frame_times holds " +
                                  std::to_string(options.frame_times.size()) + " times for " +
                                  std::to_string(frames.size()) + " frames");
    }
    times = options.frame_times;
  }
  for (size_t k = 0; k < times.size(); ++k) {
    if (!std::isfinite(times[k]) || (k > 0 && !(times[k] > times[k - 1]))) {
      return InvalidArgumentError("spacetime frame times must be finite and strictly increasing");
    }
  }
  return Status::Ok();
}

Eigen::Matrix3d Corners(const FramePositionsD& positions, int a, int b, int c) {
  Eigen::Matrix3d corners;
  corners.row(0) = positions.row(a);
  corners.row(1) = positions.row(b);
  corners.row(2) = positions.row(c);
  return corners;
}

// Edge index of every triangle side (side s joins corners s and (s+1)%3), -1 when degenerate.
std::vector<std::array<int, 3>> TriangleEdges(const MeshTopology& topology,
                                              const Triangles& triangles) {
  std::vector<std::array<int, 3>> sides(static_cast<size_t>(triangles.rows()));
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    for (int s = 0; s < 3; ++s) {
      const int slot = RingSlot(topology, triangles(t, s), triangles(t, (s + 1) % 3));
      sides[t][s] = slot >= 0 ? topology.ring_edges[slot] : -1;
    }
  }
  return sides;
}

struct CotangentContext {
  double max_cotangent;
  int* clamped;  // per-interval counter, written by one task only
};

// cot of the angle at corner `apex` opposite side (i, j), clamped.
double ClampedCotangent(const Eigen::Vector3d& apex, const Eigen::Vector3d& pi,
                        const Eigen::Vector3d& pj, const CotangentContext& context) {
  const Eigen::Vector3d u = pi - apex, v = pj - apex;
  const double cross = u.cross(v).norm();
  const double dot = u.dot(v);
  if (cross * context.max_cotangent <= std::abs(dot)) {
    ++*context.clamped;
    return dot >= 0.0 ? context.max_cotangent : -context.max_cotangent;
  }
  return dot / cross;
}

// Everything one interval [t_k, t_{k+1}] contributes; halves go to frame k ("lower") and k+1.
struct IntervalContribution {
  Eigen::VectorXd vertex_lower, vertex_upper;  // V: dual volume halves
  Eigen::VectorXd edge_lower, edge_upper;      // E: spatial edge dual area halves
  int clamped_cotangents = 0;
};

// A spatial edge dual within one face swept over the interval, as its [0, ½] and [½, 1] parts.
struct DualHalves {
  double lower = 0.0, upper = 0.0;
};

// Barycentric dual of side s: the segment from the side's midpoint to the face's centroid.
DualHalves BarycentricSideDual(const Eigen::Matrix3d& start, const Eigen::Matrix3d& end,
                               const Eigen::Vector3d& centroid0, const Eigen::Vector3d& centroid1,
                               int from, int to) {
  const Eigen::Vector3d mid0 = 0.5 * (start.row(from) + start.row(to)).transpose();
  const Eigen::Vector3d mid1 = 0.5 * (end.row(from) + end.row(to)).transpose();
  const Eigen::Vector3d segment0 = centroid0 - mid0;
  const Eigen::Vector3d change = (centroid1 - mid1) - segment0;
  return {IntegrateMovingLength(segment0, change, 0.0, 0.5),
          IntegrateMovingLength(segment0, change, 0.5, 1.0)};
}

// ∫_{β0}^{β1} of the circumcentric dual's signed length cot(θ)/2·‖e‖ of side (from, to), θ the
// angle at `apex`, by the Gauss–Legendre rule.
double CircumcentricDualIntegral(const Eigen::Matrix3d& start, const Eigen::Matrix3d& end, int from,
                                 int to, int apex, double beta0, double beta1,
                                 const GaussLegendreRule& rule, const CotangentContext& context) {
  const double half = 0.5 * (beta1 - beta0), mid = 0.5 * (beta1 + beta0);
  double sum = 0.0;
  for (Eigen::Index q = 0; q < rule.nodes.size(); ++q) {
    const Eigen::Matrix3d at = start + (mid + half * rule.nodes[q]) * (end - start);
    const Eigen::Vector3d pi = at.row(from).transpose(), pj = at.row(to).transpose();
    const double cot = ClampedCotangent(at.row(apex).transpose(), pi, pj, context);
    sum += rule.weights[q] * 0.5 * cot * (pj - pi).norm();
  }
  return half * sum;
}

// Everything that depends only on the interval, shared by its triangles.
struct IntervalInputs {
  const FramePositionsD& p0;
  const FramePositionsD& p1;
  const Eigen::MatrixXd& temporal_edge_length;  // V × intervals
  int k;
  const SpacetimeOptions& options;
  const GaussLegendreRule& rule;
  CotangentContext cot_context;
};

// Triangle t's share of interval k: its prism cell volume, the temporal edge duals of its corners
// (a third of the mid-interval area each), and the dual volume and spatial edge dual halves.
void AccumulateCell(const Triangles& triangles, const std::array<int, 3>& sides, int t,
                    const IntervalInputs& in, SpacetimeGeometry& g, IntervalContribution& part) {
  const int a = triangles(t, 0), b = triangles(t, 1), c = triangles(t, 2);
  if (a == b || b == c || a == c) return;  // no cell: measure zero
  const int k = in.k;
  const int corner[3] = {a, b, c};
  const Eigen::Matrix3d start = Corners(in.p0, a, b, c);
  const Eigen::Matrix3d end = Corners(in.p1, a, b, c);
  const double mean_length = (in.temporal_edge_length(a, k) + in.temporal_edge_length(b, k) +
                              in.temporal_edge_length(c, k)) /
                             3.0;
  const double lower = mean_length * IntegrateMovingTriangleArea(start, end, 0.0, 0.5, in.rule);
  const double upper = mean_length * IntegrateMovingTriangleArea(start, end, 0.5, 1.0, in.rule);
  g.temporal_cell_volume(t, k) = lower + upper;
  const Eigen::Matrix3d middle = 0.5 * (start + end);
  const double mid_area =
      0.5 * (middle.row(1) - middle.row(0)).cross(middle.row(2) - middle.row(0)).norm();
  for (int s = 0; s < 3; ++s) {
    part.vertex_lower[corner[s]] += lower / 3.0;
    part.vertex_upper[corner[s]] += upper / 3.0;
    g.temporal_edge_dual_area(corner[s], k) += mid_area / 3.0;
  }
  // Spatial edge duals: within this face, the segment from side s's midpoint to the centroid
  // (barycentric) or to the circumcentre (signed length cot(θ)/2·‖e‖), over both halves.
  const Eigen::Vector3d centroid0 = start.colwise().mean().transpose();
  const Eigen::Vector3d centroid1 = end.colwise().mean().transpose();
  for (int s = 0; s < 3; ++s) {
    const int edge = sides[s];
    if (edge < 0) continue;
    const int from = s, to = (s + 1) % 3, apex = (s + 2) % 3;
    DualHalves dual;
    if (in.options.spatial_dual == SpatialDual::kBarycentric) {
      dual = BarycentricSideDual(start, end, centroid0, centroid1, from, to);
    } else {
      dual.lower =
          CircumcentricDualIntegral(start, end, from, to, apex, 0.0, 0.5, in.rule, in.cot_context);
      dual.upper =
          CircumcentricDualIntegral(start, end, from, to, apex, 0.5, 1.0, in.rule, in.cot_context);
    }
    part.edge_lower[edge] += mean_length * dual.lower;
    part.edge_upper[edge] += mean_length * dual.upper;
  }
}

// Allocates every measure for the given counts; the accumulated ones start at zero.
SpacetimeGeometry EmptyGeometry(int v_count, int e_count, int t_count, std::vector<double> times) {
  const int f_count = static_cast<int>(times.size());
  const int intervals = f_count - 1;
  SpacetimeGeometry g;
  g.vertex_count = v_count;
  g.frame_count = f_count;
  g.frame_times = std::move(times);
  g.spatial_edge_length.resize(e_count, f_count);
  g.spatial_edge_dual_area.setZero(e_count, f_count);
  g.temporal_edge_length.resize(v_count, intervals);
  g.temporal_edge_dual_area.setZero(v_count, intervals);
  g.vertex_dual_volume.setZero(v_count, f_count);
  g.temporal_quad_area.resize(e_count, intervals);
  g.temporal_cell_volume.setZero(t_count, intervals);
  return g;
}

// Interval k's temporal edge lengths √(α·Δt² + ‖Δx‖²) and the areas of the quads that the spatial
// edges sweep (mean temporal length of their ends × the integrated edge length).
void ComputeTemporalEdgesAndQuads(const MeshTopology& topology, const FramePositionsD& p0,
                                  const FramePositionsD& p1, double time_length2, int k,
                                  SpacetimeGeometry& g) {
  for (int v = 0; v < topology.vertex_count; ++v) {
    g.temporal_edge_length(v, k) = std::sqrt(time_length2 + (p1.row(v) - p0.row(v)).squaredNorm());
  }
  for (int e = 0; e < topology.edge_count(); ++e) {
    const auto [i, j] = topology.edges[e];
    const Eigen::Vector3d start = (p0.row(j) - p0.row(i)).transpose();
    const Eigen::Vector3d end = (p1.row(j) - p1.row(i)).transpose();
    const double mean_length = 0.5 * (g.temporal_edge_length(i, k) + g.temporal_edge_length(j, k));
    g.temporal_quad_area(e, k) = mean_length * IntegrateMovingLength(start, end - start, 0.0, 1.0);
  }
}

// Adds each interval's halves to its two frames, in interval order.
void MergeIntervals(const std::vector<IntervalContribution>& parts, SpacetimeGeometry& g) {
  for (int k = 0; k < static_cast<int>(parts.size()); ++k) {
    g.vertex_dual_volume.col(k) += parts[k].vertex_lower;
    g.vertex_dual_volume.col(k + 1) += parts[k].vertex_upper;
    g.spatial_edge_dual_area.col(k) += parts[k].edge_lower;
    g.spatial_edge_dual_area.col(k + 1) += parts[k].edge_upper;
    g.stats.clamped_cotangents += parts[k].clamped_cotangents;
  }
  g.stats.empty_vertex_duals = static_cast<int>((g.vertex_dual_volume.array() <= 0.0).count());
}

}  // namespace

StatusOr<SpacetimeGeometry> ComputeSpacetimeGeometry(const MeshTopology& topology,
                                                     const Triangles& triangles,
                                                     std::span<const FramePositionsD> frames,
                                                     const SpacetimeOptions& options) {
  std::vector<double> times;
  DMC_RETURN_IF_ERROR(ValidateInputs(topology, triangles, frames, options, times));
  const int e_count = topology.edge_count();
  const int t_count = static_cast<int>(triangles.rows());
  const int f_count = static_cast<int>(frames.size());
  SpacetimeGeometry g = EmptyGeometry(topology.vertex_count, e_count, t_count, times);

  tbb::parallel_for(0, f_count, [&](int k) {
    for (int e = 0; e < e_count; ++e) {
      const auto [i, j] = topology.edges[e];
      g.spatial_edge_length(e, k) = (frames[k].row(j) - frames[k].row(i)).norm();
    }
  });

  const std::vector<std::array<int, 3>> sides = TriangleEdges(topology, triangles);
  const GaussLegendreRule rule = MakeGaussLegendreRule(options.quadrature_points);
  std::vector<IntervalContribution> parts(static_cast<size_t>(f_count - 1));
  tbb::parallel_for(0, f_count - 1, [&](int k) {
    const double dt = times[k + 1] - times[k];
    ComputeTemporalEdgesAndQuads(topology, frames[k], frames[k + 1], options.alpha * dt * dt, k, g);
    IntervalContribution& part = parts[k];
    part.vertex_lower.setZero(topology.vertex_count);
    part.vertex_upper.setZero(topology.vertex_count);
    part.edge_lower.setZero(e_count);
    part.edge_upper.setZero(e_count);
    const IntervalInputs inputs{frames[k],
                                frames[k + 1],
                                g.temporal_edge_length,
                                k,
                                options,
                                rule,
                                {options.max_cotangent, &part.clamped_cotangents}};
    for (int t = 0; t < t_count; ++t) AccumulateCell(triangles, sides[t], t, inputs, g, part);
  });
  MergeIntervals(parts, g);
  return g;
}

}  // namespace dmc

// Visiting every triangle corner through the topology's edge/opposite table, so the geometric
// formulas need only MeshTopology and positions (which is all a decoder holds).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "dmc/sequence.h"
#include "dmc/topology.h"

namespace dmc::operators_internal {

// Calls visit(e, o, i, j) once per (edge e = (i, j), opposite vertex o), i.e. once per triangle
// corner o: a manifold triangle {i, j, o} is reached through each of its three edges, each time
// with a different corner. Triangles beyond the second on a non-manifold edge are not kept by
// MeshTopology, so they are not visited.
template <typename Visit>
void ForEachCorner(const MeshTopology& topology, Visit&& visit) {
  for (int e = 0; e < topology.edge_count(); ++e) {
    const int i = topology.edges[e][0], j = topology.edges[e][1];
    for (int side = 0; side < 2; ++side) {
      const int o = topology.edge_opposite[e][side];
      if (o >= 0) visit(e, o, i, j);
    }
  }
}

inline Eigen::Vector3d Position(const FramePositionsD& positions, int v) {
  return positions.row(v).transpose();
}

// True when the triangle spanned by a and b (edge vectors from one corner) has (numerically)
// zero area: the sine of the corner angle, or an edge length, vanishes at double precision.
inline bool IsDegenerateCorner(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double cross = a.cross(b).norm();
  return !(cross > 1e-12 * (a.squaredNorm() + b.squaredNorm()));
}

// cot of the angle between a and b, clamped to ±max_cotangent without ever dividing by zero.
// `clamped` is set when the clamp (or a degenerate zero-length side) decided the value.
inline double ClampedCotangent(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               double max_cotangent, bool* clamped) {
  const double dot = a.dot(b);
  const double cross = a.cross(b).norm();
  *clamped = false;
  if (!(std::abs(dot) < max_cotangent * cross)) {
    *clamped = true;
    if (dot == 0.0) return 0.0;  // a zero-length side: no angle at all
    return dot > 0.0 ? max_cotangent : -max_cotangent;
  }
  return dot / cross;
}

}  // namespace dmc::operators_internal

// Small time-varying meshes with known centres for the TVM tests: UV spheres whose tessellation
// changes every frame, centres on a lattice inside them, and rigid motions per frame.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "dmc/tvm.h"

namespace dmc::tvm::testing {

// A closed UV sphere (outward triangles) with `rings` latitude bands and `segments` longitudes.
inline TvmFrame UvSphere(const Eigen::Vector3d& centre, double radius, int rings, int segments) {
  TvmFrame frame;
  const int vertices = 2 + (rings - 1) * segments;
  frame.positions.resize(vertices, 3);
  frame.positions.row(0) = (centre + Eigen::Vector3d(0, 0, radius)).transpose();
  frame.positions.row(vertices - 1) = (centre - Eigen::Vector3d(0, 0, radius)).transpose();
  for (int r = 1; r < rings; ++r) {
    const double theta = std::numbers::pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2.0 * std::numbers::pi * s / segments;
      const Eigen::Vector3d p(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
      frame.positions.row(1 + (r - 1) * segments + s) = (centre + radius * p).transpose();
    }
  }
  std::vector<std::array<int32_t, 3>> tris;
  auto ring_vertex = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) {
    tris.push_back({0, ring_vertex(1, s), ring_vertex(1, s + 1)});
    tris.push_back({vertices - 1, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s)});
  }
  for (int r = 1; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      tris.push_back({ring_vertex(r, s), ring_vertex(r + 1, s), ring_vertex(r + 1, s + 1)});
      tris.push_back({ring_vertex(r, s), ring_vertex(r + 1, s + 1), ring_vertex(r, s + 1)});
    }
  }
  frame.triangles.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t) {
    for (int c = 0; c < 3; ++c) frame.triangles(static_cast<Eigen::Index>(t), c) = tris[t][c];
  }
  return frame;
}

// Lattice points of spacing `step` strictly inside a ball (|p - centre| <= radius - step / 2).
inline std::vector<Eigen::Vector3d> BallLattice(const Eigen::Vector3d& centre, double radius,
                                                double step) {
  std::vector<Eigen::Vector3d> points;
  const int half = static_cast<int>(std::floor(radius / step));
  for (int x = -half; x <= half; ++x) {
    for (int y = -half; y <= half; ++y) {
      for (int z = -half; z <= half; ++z) {
        const Eigen::Vector3d p = step * Eigen::Vector3d(x, y, z);
        if (p.norm() <= radius - 0.5 * step) points.push_back(centre + p);
      }
    }
  }
  return points;
}

inline TvmFrame Transformed(const TvmFrame& frame, const Eigen::Isometry3d& motion) {
  TvmFrame moved = frame;
  for (int v = 0; v < frame.vertex_count(); ++v) {
    moved.positions.row(v) = (motion * Eigen::Vector3d(frame.positions.row(v))).transpose();
  }
  return moved;
}

// A body moved rigidly: frame f is motion(f) applied to a sphere re-tessellated per frame
// (rings and segments change with f), and the centres are the lattice moved the same way.
struct RigidBodySequence {
  TimeVaryingMesh mesh;
  CentreTrajectories centres;
  std::vector<Eigen::Isometry3d> motions;  // frame f = motions[f] * rest
};

inline RigidBodySequence MakeRigidBody(int frames,
                                       const std::function<Eigen::Isometry3d(int)>& motion,
                                       double radius = 1.0, double step = 0.25) {
  RigidBodySequence sequence;
  const auto lattice = BallLattice(Eigen::Vector3d::Zero(), radius, step);
  for (int f = 0; f < frames; ++f) {
    const Eigen::Isometry3d m = motion(f);
    sequence.motions.push_back(m);
    sequence.mesh.frames.push_back(
        Transformed(UvSphere(Eigen::Vector3d::Zero(), radius, 10 + f % 3, 14 + 2 * (f % 4)), m));
    FramePositionsD centres(static_cast<Eigen::Index>(lattice.size()), 3);
    for (size_t i = 0; i < lattice.size(); ++i) {
      centres.row(static_cast<Eigen::Index>(i)) = (m * lattice[i]).transpose();
    }
    sequence.centres.positions.push_back(centres);
  }
  return sequence;
}

inline Eigen::Isometry3d RigidMotion(double angle, const Eigen::Vector3d& axis,
                                     const Eigen::Vector3d& translation) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  m.translation() = translation;
  return m;
}

// Two balls of radius 0.5 on the x axis: far apart in the first and last frames, with a gap of
// `closest_gap` in the middle frame. Body A is centred at -x(t), B at +x(t); B also spins about z.
// Centres 0 .. a_count-1 belong to A, the rest to B; likewise each frame's vertices
// 0 .. a_vertices[f]-1 are A's.
struct TwoBodySequence {
  TimeVaryingMesh mesh;
  CentreTrajectories centres;
  int a_count = 0;
  std::vector<int> a_vertices;
  std::vector<double> gaps;
};

inline TwoBodySequence MakeTwoBodies(int frames, double closest_gap) {
  TwoBodySequence sequence;
  const double radius = 0.5, step = 0.2, far_gap = 2.0;
  const auto lattice = BallLattice(Eigen::Vector3d::Zero(), radius, step);
  sequence.a_count = static_cast<int>(lattice.size());
  for (int f = 0; f < frames; ++f) {
    const double t = frames > 1 ? static_cast<double>(f) / (frames - 1) : 0.0;
    const double gap = closest_gap + (far_gap - closest_gap) * std::abs(2.0 * t - 1.0);
    sequence.gaps.push_back(gap);
    const double half = radius + 0.5 * gap;
    const Eigen::Isometry3d a = RigidMotion(0.0, Eigen::Vector3d::UnitZ(), {-half, 0, 0});
    const Eigen::Isometry3d b = RigidMotion(0.3 * f, Eigen::Vector3d::UnitZ(), {half, 0, 0});
    const TvmFrame body_a = Transformed(UvSphere({0, 0, 0}, radius, 8 + f % 2, 12 + f % 3), a);
    const TvmFrame body_b = Transformed(UvSphere({0, 0, 0}, radius, 9 - f % 2, 13 - f % 3), b);
    TvmFrame both;
    both.positions.resize(body_a.vertex_count() + body_b.vertex_count(), 3);
    both.positions << body_a.positions, body_b.positions;
    both.triangles.resize(body_a.triangle_count() + body_b.triangle_count(), 3);
    both.triangles << body_a.triangles, (body_b.triangles.array() + body_a.vertex_count()).matrix();
    sequence.a_vertices.push_back(body_a.vertex_count());
    sequence.mesh.frames.push_back(both);
    FramePositionsD centres(2 * static_cast<Eigen::Index>(lattice.size()), 3);
    for (size_t i = 0; i < lattice.size(); ++i) {
      centres.row(static_cast<Eigen::Index>(i)) = (a * lattice[i]).transpose();
      centres.row(static_cast<Eigen::Index>(i + lattice.size())) = (b * lattice[i]).transpose();
    }
    sequence.centres.positions.push_back(centres);
  }
  return sequence;
}

}  // namespace dmc::tvm::testing

// The collision example of the paper's Figs. 10 and 12: a box and a sphere that approach along x,
// touch at the middle frame and separate again (to a different gap, so the sequence does not loop
// by itself), each re-tessellated every frame, with volume centres on lattices inside both.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include "synth/random.h"
#include "synth/shapes.h"
#include "synth/tvm_shapes.h"

namespace dmc::synth {

namespace {

constexpr uint64_t kRandomStream = 202;
constexpr double kBoxHalf = 0.5;
constexpr double kSphereRadius = 0.5;
constexpr double kStartGap = 1.5;
constexpr double kEndGap = 1.2;

// The surface of the cube [-0.5, 0.5]^3 with n x n quads per face. Vertices are shared along the
// cube's edges (welded by their integer grid coordinates, so no duplicates); outward triangles.
tvm::TvmFrame BuildCube(int n, bool flip) {
  std::map<std::array<int, 3>, int32_t> index_of;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int32_t, 3>> triangles;
  auto vertex = [&](const std::array<int, 3>& grid) {
    const auto [it, inserted] = index_of.emplace(grid, static_cast<int32_t>(points.size()));
    if (inserted) {
      points.emplace_back(-kBoxHalf + 2.0 * kBoxHalf * grid[0] / n,
                          -kBoxHalf + 2.0 * kBoxHalf * grid[1] / n,
                          -kBoxHalf + 2.0 * kBoxHalf * grid[2] / n);
    }
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    // (u, v, axis) is right-handed, so counter-clockwise in (u, v) faces +axis.
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (const int side : {0, n}) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          auto at = [&](int di, int dj) {
            std::array<int, 3> grid{};
            grid[axis] = side;
            grid[u] = i + di;
            grid[v] = j + dj;
            return vertex(grid);
          };
          const int32_t a = at(0, 0), b = at(1, 0), c = at(1, 1), d = at(0, 1);
          std::array<std::array<int32_t, 3>, 2> quad =
              flip ? std::array<std::array<int32_t, 3>, 2>{{{a, b, d}, {b, c, d}}}
                   : std::array<std::array<int32_t, 3>, 2>{{{a, b, c}, {a, c, d}}};
          for (auto& triangle : quad) {
            if (side == 0)
              std::swap(triangle[1], triangle[2]);  // the -axis face looks the other way
            triangles.push_back(triangle);
          }
        }
      }
    }
  }
  tvm::TvmFrame frame;
  frame.positions.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t p = 0; p < points.size(); ++p) {
    frame.positions.row(static_cast<Eigen::Index>(p)) = points[p].transpose();
  }
  frame.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) frame.triangles(static_cast<Eigen::Index>(t), c) = triangles[t][c];
  }
  return frame;
}

tvm::TvmFrame BuildSphere(int segments) {
  CapsuleLayout layout;
  layout.segments = segments;
  layout.body_intervals = 0;
  layout.cap_rings = std::max(1, segments / 4 - 1);
  const RestMesh mesh = BuildCapsule(kSphereRadius, 0.0, layout);
  return {mesh.positions, mesh.triangles};
}

// Lattice points of spacing `step` inside the cube (centred at the origin) or the sphere, at least
// step / 2 from the surface: volume centres that cover the body evenly.
std::vector<Eigen::Vector3d> Lattice(double step, bool sphere) {
  std::vector<Eigen::Vector3d> points;
  if (sphere) {
    const int half = static_cast<int>(std::floor(kSphereRadius / step));
    for (int x = -half; x <= half; ++x) {
      for (int y = -half; y <= half; ++y) {
        for (int z = -half; z <= half; ++z) {
          const Eigen::Vector3d p = step * Eigen::Vector3d(x, y, z);
          if (p.norm() <= kSphereRadius - 0.5 * step) points.push_back(p);
        }
      }
    }
    return points;
  }
  // c points per axis, symmetric about 0: the outermost is (c - 1) / 2 steps out, inset >= step
  // / 2.
  const int count = std::max(1, static_cast<int>(std::floor(2.0 * kBoxHalf / step)));
  auto coordinate = [&](int i) { return (i - 0.5 * (count - 1)) * step; };
  for (int x = 0; x < count; ++x) {
    for (int y = 0; y < count; ++y) {
      for (int z = 0; z < count; ++z)
        points.emplace_back(coordinate(x), coordinate(y), coordinate(z));
    }
  }
  return points;
}

}  // namespace

TimeVaryingSynthesis GenerateCollision(const TimeVaryingSynthOptions& options) {
  SeededRandom random(options.seed, kRandomStream);
  const double box_spin = random.Uniform(0.4, 1.0);     // rad over the sequence, about x
  const double sphere_spin = random.Uniform(1.0, 2.0);  // rad over the sequence, about z

  // Half the vertices on each body: a cube with n x n quads per face has 6 n^2 + 2 vertices; the
  // sphere with s segments about s^2 / 2.
  const int cube_n =
      std::max(2, static_cast<int>(std::lround(std::sqrt(options.resolution / 12.0))));
  const int sphere_segments = std::max(
      8, static_cast<int>(std::lround(std::sqrt(static_cast<double>(options.resolution)))));
  const double volume = 8.0 * kBoxHalf * kBoxHalf * kBoxHalf +
                        4.0 / 3.0 * std::numbers::pi * std::pow(kSphereRadius, 3);
  double step = std::cbrt(volume / options.centres);
  // Lattice counts are a step function of the step: rescale a few times, keep the closest count.
  double best_step = step;
  double best_error = std::numeric_limits<double>::infinity();
  for (int attempt = 0; attempt < 12; ++attempt) {
    const double count =
        static_cast<double>(Lattice(step, false).size() + Lattice(step, true).size());
    if (std::abs(count - options.centres) < best_error) {
      best_error = std::abs(count - options.centres);
      best_step = step;
    }
    step *= std::cbrt(std::max(count, 1.0) / options.centres);
  }
  const std::vector<Eigen::Vector3d> box_centres = Lattice(best_step, false);
  const std::vector<Eigen::Vector3d> sphere_centres = Lattice(best_step, true);

  TimeVaryingSynthesis result;
  result.mesh.name = "collision";
  result.mesh.frame_rate = kFrameRate;
  const int frames = options.frames;
  for (int f = 0; f < frames; ++f) {
    const double t = frames > 1 ? static_cast<double>(f) / (frames - 1) : 0.0;
    // Gap between the box's +x face and the sphere: closes linearly, 0 at t = 1/2, then opens.
    const double gap = t < 0.5 ? kStartGap * (1.0 - 2.0 * t) : kEndGap * (2.0 * t - 1.0);
    Eigen::Isometry3d box = Eigen::Isometry3d::Identity();
    box.linear() = Eigen::AngleAxisd(box_spin * t, Eigen::Vector3d::UnitX()).toRotationMatrix();
    box.translation() = Eigen::Vector3d(-kBoxHalf - 0.5 * gap, 0.0, 0.0);
    Eigen::Isometry3d sphere = Eigen::Isometry3d::Identity();
    sphere.linear() =
        Eigen::AngleAxisd(sphere_spin * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    sphere.translation() = Eigen::Vector3d(kSphereRadius + 0.5 * gap, 0.0, 0.0);

    // Re-tessellated every frame: the cube's grid and the sphere's segment count cycle.
    const tvm::TvmFrame box_mesh = MovedFrame(BuildCube(cube_n + f % 3, f % 2 == 1), box);
    const tvm::TvmFrame sphere_mesh =
        MovedFrame(BuildSphere(sphere_segments + 2 * (f % 3)), sphere);
    tvm::TvmFrame both;
    both.positions.resize(box_mesh.vertex_count() + sphere_mesh.vertex_count(), 3);
    both.positions << box_mesh.positions, sphere_mesh.positions;
    both.triangles.resize(box_mesh.triangle_count() + sphere_mesh.triangle_count(), 3);
    both.triangles << box_mesh.triangles,
        (sphere_mesh.triangles.array() + box_mesh.vertex_count()).matrix();
    result.mesh.frames.push_back(std::move(both));

    FramePositionsD centres(static_cast<Eigen::Index>(box_centres.size() + sphere_centres.size()),
                            3);
    centres << MovedPoints(box_centres, box), MovedPoints(sphere_centres, sphere);
    result.centres.positions.push_back(std::move(centres));
  }
  return result;
}

}  // namespace dmc::synth

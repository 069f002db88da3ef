// The rotating pentagonal prism of the paper's Figs. 8, 9 and 11: a closed prism resampled with a
// different grid every frame (so no two consecutive frames share connectivity), turning about its
// axis, with volume centres on a lattice inside it.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "synth/random.h"
#include "synth/shapes.h"
#include "synth/tvm_shapes.h"

namespace dmc::synth {

namespace {

constexpr uint64_t kRandomStream = 201;
constexpr int kSides = 5;
constexpr double kHalfHeight = 1.0;

Eigen::Vector2d Corner(int side) {
  const double angle = 2.0 * std::numbers::pi * side / kSides;
  return {std::cos(angle), std::sin(angle)};
}

// Vertex layout of a prism with `per_side` intervals along each pentagon edge and `rows` along
// the height: side rows 0..rows (row 0 at the bottom), then the interior rings j = 1..m-1 of the
// bottom cap and the top cap, then the two cap centres.
struct PrismLayout {
  PrismLayout(int per_side, int rows_) : m(per_side), rows(rows_) {}
  int m;
  int rows;
  int ring = kSides * m;  // vertices on one pentagon outline
  int cap_interior = kSides * m * (m - 1) / 2;
  int bottom_interior = ring * (rows + 1);
  int top_interior = bottom_interior + cap_interior;
  int bottom_centre = top_interior + cap_interior;
  int top_centre = bottom_centre + 1;
  int vertex_count() const { return top_centre + 1; }
  int ring_start(int j) const { return kSides * j * (j - 1) / 2; }  // offset of ring j >= 1
  // Vertex `index` (taken modulo the ring's size) of cap ring j: ring 0 is the centre, ring m the
  // outline.
  int cap_vertex(bool top, int j, int index) const {
    if (j == 0) return top ? top_centre : bottom_centre;
    index %= kSides * j;
    if (j == m) return (top ? rows * ring : 0) + index;
    return (top ? top_interior : bottom_interior) + ring_start(j) + index;
  }
};

void PlacePrismVertices(const PrismLayout& layout, tvm::TvmFrame& frame) {
  const int m = layout.m;
  frame.positions.resize(layout.vertex_count(), 3);
  auto outline = [&](int j, int index) {  // point `index` of the ring at scale j / m
    const int side = index / std::max(j, 1);
    const int step = index % std::max(j, 1);
    const Eigen::Vector2d p =
        Corner(side) + (Corner(side + 1) - Corner(side)) * (static_cast<double>(step) / j);
    return Eigen::Vector2d(p * (static_cast<double>(j) / m));
  };
  for (int row = 0; row <= layout.rows; ++row) {
    const double z = -kHalfHeight + 2.0 * kHalfHeight * row / layout.rows;
    for (int i = 0; i < layout.ring; ++i) {
      const Eigen::Vector2d p = outline(m, i);
      frame.positions.row(row * layout.ring + i) << p.x(), p.y(), z;
    }
  }
  for (int j = 1; j < m; ++j) {
    for (int i = 0; i < kSides * j; ++i) {
      const Eigen::Vector2d p = outline(j, i);
      frame.positions.row(layout.bottom_interior + layout.ring_start(j) + i) << p.x(), p.y(),
          -kHalfHeight;
      frame.positions.row(layout.top_interior + layout.ring_start(j) + i) << p.x(), p.y(),
          kHalfHeight;
    }
  }
  frame.positions.row(layout.bottom_centre) << 0.0, 0.0, -kHalfHeight;
  frame.positions.row(layout.top_centre) << 0.0, 0.0, kHalfHeight;
}

// Caps: between ring j-1 and ring j, sector by sector.
void AppendCapTriangles(const PrismLayout& layout, std::vector<std::array<int32_t, 3>>& triangles) {
  for (const bool top : {false, true}) {
    auto add = [&](int a, int b, int c) {
      // Counter-clockwise seen from +z is outward on the top cap; reversed on the bottom.
      if (top) {
        triangles.push_back({a, b, c});
      } else {
        triangles.push_back({a, c, b});
      }
    };
    for (int j = 1; j <= layout.m; ++j) {
      for (int side = 0; side < kSides; ++side) {
        for (int t = 0; t < j; ++t) {
          const int outer = layout.cap_vertex(top, j, side * j + t);
          const int outer_next = layout.cap_vertex(top, j, side * j + t + 1);
          add(outer, outer_next, layout.cap_vertex(top, j - 1, side * (j - 1) + t));
          if (t + 1 < j) {
            add(layout.cap_vertex(top, j - 1, side * (j - 1) + t), outer_next,
                layout.cap_vertex(top, j - 1, side * (j - 1) + t + 1));
          }
        }
      }
    }
  }
}

// A closed pentagonal prism: `per_side` intervals along each pentagon edge, `rows` intervals along
// the height; caps are concentric pentagonal rings. `flip` mirrors the side quads' diagonals.
// Outward counter-clockwise triangles.
tvm::TvmFrame BuildPrism(int per_side, int rows, bool flip) {
  const PrismLayout layout(per_side, rows);
  const int ring = layout.ring;
  tvm::TvmFrame frame;
  PlacePrismVertices(layout, frame);
  std::vector<std::array<int32_t, 3>> triangles;
  for (int row = 0; row < rows; ++row) {
    for (int i = 0; i < ring; ++i) {
      const int a = row * ring + i, b = row * ring + (i + 1) % ring;
      const int c = b + ring, d = a + ring;
      if (flip) {
        triangles.push_back({a, b, d});
        triangles.push_back({b, c, d});
      } else {
        triangles.push_back({a, b, c});
        triangles.push_back({a, c, d});
      }
    }
  }
  AppendCapTriangles(layout, triangles);
  frame.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) frame.triangles(static_cast<Eigen::Index>(t), c) = triangles[t][c];
  }
  return frame;
}

bool InsidePentagon(const Eigen::Vector2d& p, double inset) {
  for (int side = 0; side < kSides; ++side) {
    const Eigen::Vector2d a = Corner(side), b = Corner(side + 1);
    const Eigen::Vector2d edge = (b - a).normalized();
    const Eigen::Vector2d inward(-edge.y(), edge.x());
    if ((p - a).dot(inward) < inset) return false;
  }
  return true;
}

std::vector<Eigen::Vector3d> PrismCentres(int target) {
  const double area = 0.5 * kSides * std::sin(2.0 * std::numbers::pi / kSides);
  const double volume = area * 2.0 * kHalfHeight;
  double step = std::cbrt(volume / target);
  std::vector<Eigen::Vector3d> points, best;
  // The inset lattice holds fewer points than volume / step^3, and its count is a step function
  // of the step: rescale a few times and keep the count closest to the target.
  for (int attempt = 0; attempt < 12; ++attempt) {
    points.clear();
    const int half_xy = static_cast<int>(std::ceil(1.0 / step));
    const int half_z = static_cast<int>(std::floor((kHalfHeight - 0.5 * step) / step));
    for (int x = -half_xy; x <= half_xy; ++x) {
      for (int y = -half_xy; y <= half_xy; ++y) {
        const Eigen::Vector2d p(step * x, step * y);
        if (!InsidePentagon(p, 0.5 * step)) continue;
        for (int z = -half_z; z <= half_z; ++z) points.emplace_back(p.x(), p.y(), step * z);
      }
    }
    if (best.empty() || std::abs(static_cast<int>(points.size()) - target) <
                            std::abs(static_cast<int>(best.size()) - target)) {
      best = points;
    }
    step *= std::cbrt(std::max(static_cast<double>(points.size()), 1.0) / target);
  }
  return best;
}

}  // namespace

TimeVaryingSynthesis GeneratePrism(const TimeVaryingSynthOptions& options) {
  SeededRandom random(options.seed, kRandomStream);
  const double speed = random.Uniform(0.6, 1.2);  // rad/s about the axis
  const double phase = random.Phase();

  // Side intervals per pentagon edge whose mesh is closest to the requested vertex count; rows
  // keep the side quads near square (edge 2 sin 36° ~ 1.18, height 2).
  auto rows_for = [](int per_side) {
    return std::max(2, static_cast<int>(std::lround(1.7 * per_side)));
  };
  auto vertices_for = [&](int per_side) {
    return kSides * per_side * (rows_for(per_side) + 1) + kSides * per_side * (per_side - 1) + 2;
  };
  int base = 2;
  while (std::abs(vertices_for(base + 1) - options.resolution) <
         std::abs(vertices_for(base) - options.resolution)) {
    ++base;
  }
  const std::vector<Eigen::Vector3d> centres = PrismCentres(options.centres);

  TimeVaryingSynthesis result;
  result.mesh.name = "prism";
  result.mesh.frame_rate = kFrameRate;
  for (int f = 0; f < options.frames; ++f) {
    // A different sampling each frame: the row count cycles through four values and the quad
    // diagonals alternate, so consecutive frames never share connectivity.
    const int per_side = base;
    const int rows = std::max(2, rows_for(base) + (f % 4) - 1);
    const tvm::TvmFrame rest = BuildPrism(per_side, rows, f % 2 == 1);
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    motion.linear() = Eigen::AngleAxisd(phase + speed * f / kFrameRate, Eigen::Vector3d::UnitZ())
                          .toRotationMatrix();
    result.mesh.frames.push_back(MovedFrame(rest, motion));
    result.centres.positions.push_back(MovedPoints(centres, motion));
  }
  return result;
}

}  // namespace dmc::synth

#include "synth/shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numbers>
#include <utility>

#include "synth/grid_triangles.h"

namespace dmc::synth {

namespace {

constexpr double kPi = std::numbers::pi;

}  // namespace

CapsuleLayout LayoutCapsule(double radius, double length, double spacing, int min_segments) {
  CapsuleLayout layout;
  const int natural_segments = static_cast<int>(std::lround(2.0 * kPi * radius / spacing));
  layout.segments = std::max(min_segments, natural_segments);
  // Along the axis use the realised arc spacing, so the quads stay close to square, unless the
  // ring was refined up to min_segments: then a thin part keeps the requested spacing lengthwise
  // instead of multiplying its rings.
  const double arc_spacing = 2.0 * kPi * radius / layout.segments;
  const double axial_spacing = natural_segments >= min_segments ? arc_spacing : spacing;
  const int cap_intervals =
      std::max(1, static_cast<int>(std::lround(0.5 * kPi * radius / axial_spacing)));
  layout.cap_rings = cap_intervals - 1;
  layout.body_intervals =
      length > 0.0 ? std::max(1, static_cast<int>(std::lround(length / axial_spacing))) : 0;
  return layout;
}

RestMesh BuildCapsule(double radius, double length, const CapsuleLayout& layout) {
  const int segments = layout.segments;
  const int rings = layout.ring_count();
  const int cap_intervals = layout.cap_rings + 1;
  RestMesh mesh;
  mesh.positions.resize(layout.vertex_count(), 3);
  mesh.positions.row(0) << 0.0, 0.0, -radius;
  mesh.positions.row(layout.vertex_count() - 1) << 0.0, 0.0, length + radius;
  for (int ring = 0; ring < rings; ++ring) {
    double z = 0.0;
    double ring_radius = radius;
    if (ring < layout.cap_rings) {  // bottom cap, polar angle measured from the bottom pole
      const double polar = (ring + 1) * 0.5 * kPi / cap_intervals;
      z = -radius * std::cos(polar);
      ring_radius = radius * std::sin(polar);
    } else if (ring <= layout.cap_rings + layout.body_intervals) {  // cylindrical body
      const int step = ring - layout.cap_rings;
      z = layout.body_intervals > 0 ? length * step / layout.body_intervals : 0.0;
    } else {  // top cap, elevation measured from the top equator
      const int step = ring - layout.cap_rings - layout.body_intervals;
      const double elevation = step * 0.5 * kPi / cap_intervals;
      z = length + radius * std::sin(elevation);
      ring_radius = radius * std::cos(elevation);
    }
    for (int j = 0; j < segments; ++j) {
      const double azimuth = 2.0 * kPi * j / segments;
      mesh.positions.row(1 + ring * segments + j) << ring_radius * std::cos(azimuth),
          ring_radius * std::sin(azimuth), z;
    }
  }

  const int bottom_pole = 0;
  const int top_pole = layout.vertex_count() - 1;
  auto ring_vertex = [&](int ring, int j) { return 1 + ring * segments + (j % segments); };
  mesh.triangles.resize(2 * segments * rings, 3);
  int t = 0;
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.row(t++) << bottom_pole, ring_vertex(0, j + 1), ring_vertex(0, j);
  }
  // Between a lower ring a and an upper ring b, (a_j, a_j+1, b_j+1) and (a_j, b_j+1, b_j) have
  // normals along +azimuth × +z, i.e. radially outwards.
  for (int ring = 0; ring + 1 < rings; ++ring) {
    for (int j = 0; j < segments; ++j) {
      const int a0 = ring_vertex(ring, j), a1 = ring_vertex(ring, j + 1);
      const int b0 = ring_vertex(ring + 1, j), b1 = ring_vertex(ring + 1, j + 1);
      mesh.triangles.row(t++) << a0, a1, b1;
      mesh.triangles.row(t++) << a0, b1, b0;
    }
  }
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.row(t++) << ring_vertex(rings - 1, j), ring_vertex(rings - 1, j + 1), top_pole;
  }
  return mesh;
}

namespace {

// The regular icosahedron with corners (0, ±1, ±φ) and cyclic permutations, faces oriented
// outwards.
struct Icosahedron {
  std::array<Eigen::Vector3d, 12> corners;
  std::array<std::array<int, 3>, 20> faces;
};

Icosahedron OutwardIcosahedron() {
  const double phi = std::numbers::phi;
  Icosahedron ico{
      {{
          {-1, phi, 0},
          {1, phi, 0},
          {-1, -phi, 0},
          {1, -phi, 0},
          {0, -1, phi},
          {0, 1, phi},
          {0, -1, -phi},
          {0, 1, -phi},
          {phi, 0, -1},
          {phi, 0, 1},
          {-phi, 0, -1},
          {-phi, 0, 1},
      }},
      {{
          {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
          {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
          {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1},
      }}};
  // Orient every face outwards: the icosahedron is centred on the origin, so a face's normal must
  // point the same way as its centroid.
  for (auto& face : ico.faces) {
    const Eigen::Vector3d& a = ico.corners[face[0]];
    const Eigen::Vector3d& b = ico.corners[face[1]];
    const Eigen::Vector3d& c = ico.corners[face[2]];
    if ((b - a).cross(c - a).dot(a + b + c) < 0.0) std::swap(face[1], face[2]);
  }
  return ico;
}

}  // namespace

RestMesh BuildGeodesicSphere(int frequency) {
  const int n = frequency;
  const Icosahedron ico = OutwardIcosahedron();
  const auto& corners = ico.corners;
  const auto& faces = ico.faces;

  const int vertex_count = 10 * n * n + 2;
  RestMesh mesh;
  mesh.positions.resize(vertex_count, 3);
  int next_vertex = 0;
  auto add_vertex = [&](const Eigen::Vector3d& point) {
    mesh.positions.row(next_vertex) = point.normalized().transpose();
    return next_vertex++;
  };
  std::array<int, 12> corner_vertex{};
  for (int c = 0; c < 12; ++c) corner_vertex[c] = add_vertex(corners[c]);
  // The n - 1 inner vertices of each icosahedron edge (u < v) are numbered from u to v, so both
  // faces sharing the edge find the same vertices.
  std::map<std::pair<int, int>, int> edge_first_vertex;
  for (const auto& face : faces) {
    for (int k = 0; k < 3; ++k) {
      const int u = std::min(face[k], face[(k + 1) % 3]);
      const int v = std::max(face[k], face[(k + 1) % 3]);
      if (edge_first_vertex.count({u, v}) != 0) continue;
      edge_first_vertex[{u, v}] = next_vertex;
      for (int step = 1; step < n; ++step) {
        add_vertex(corners[u] + (corners[v] - corners[u]) * (static_cast<double>(step) / n));
      }
    }
  }
  // Vertex `step` steps of n along the corner edge from `from` to `to`.
  auto edge_vertex = [&](int from, int to, int step) {
    if (from < to) return edge_first_vertex.at({from, to}) + step - 1;
    return edge_first_vertex.at({to, from}) + (n - step) - 1;
  };

  mesh.triangles.resize(20 * n * n, 3);
  int t = 0;
  std::vector<int> local((n + 1) * (n + 1), -1);  // (i, j) → vertex, i + j ≤ n
  for (const auto& face : faces) {
    const int a = face[0], b = face[1], c = face[2];
    // Point (i, j) of the face is A + i/n (B - A) + j/n (C - A).
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        int vertex;
        if (i == 0 && j == 0) {
          vertex = corner_vertex[a];
        } else if (i == n) {
          vertex = corner_vertex[b];
        } else if (j == n) {
          vertex = corner_vertex[c];
        } else if (j == 0) {
          vertex = edge_vertex(a, b, i);
        } else if (i == 0) {
          vertex = edge_vertex(a, c, j);
        } else if (i + j == n) {
          vertex = edge_vertex(b, c, j);
        } else {
          vertex =
              add_vertex(corners[a] + (corners[b] - corners[a]) * (static_cast<double>(i) / n) +
                         (corners[c] - corners[a]) * (static_cast<double>(j) / n));
        }
        local[i * (n + 1) + j] = vertex;
      }
    }
    auto at = [&](int i, int j) { return local[i * (n + 1) + j]; };
    for (int i = 0; i < n; ++i) {
      for (int j = 0; i + j < n; ++j) {
        mesh.triangles.row(t++) << at(i, j), at(i + 1, j), at(i, j + 1);
        if (i + j + 1 < n) mesh.triangles.row(t++) << at(i + 1, j), at(i + 1, j + 1), at(i, j + 1);
      }
    }
  }
  return mesh;
}

RestMesh BuildGrid(int columns, int rows, double width, double height) {
  RestMesh mesh;
  mesh.positions.resize(columns * rows, 3);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c) {
      mesh.positions.row(r * columns + c) << width * c / (columns - 1), height * r / (rows - 1),
          0.0;
    }
  }
  mesh.triangles = GridTriangles(columns, rows, GridDiagonals::kAlternating);
  return mesh;
}

double FitSpacing(const std::function<int(double spacing)>& count_for_spacing, int target,
                  double initial) {
  double spacing = initial;
  double best_spacing = initial;
  long best_error = -1;
  for (int iteration = 0; iteration < 12; ++iteration) {
    const int count = count_for_spacing(spacing);
    const long error = std::labs(static_cast<long>(count) - target);
    if (best_error < 0 || error < best_error) {
      best_error = error;
      best_spacing = spacing;
    }
    if (error == 0) break;
    spacing *= std::sqrt(static_cast<double>(count) / target);
  }
  return best_spacing;
}

MeshSequence AnimateFrames(const RestMesh& mesh, int frames, std::string name,
                           const std::function<void(double time, FramePositionsD& out)>& pose) {
  MeshSequence sequence(mesh.vertex_count(), mesh.triangles, frames);
  sequence.name = std::move(name);
  sequence.frame_rate = kFrameRate;
  FramePositionsD positions(mesh.vertex_count(), 3);
  for (int f = 0; f < frames; ++f) {
    pose(f / kFrameRate, positions);
    sequence.frame(f) = positions.cast<float>();
  }
  return sequence;
}

}  // namespace dmc::synth

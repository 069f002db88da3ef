// Rest-pose meshes the synthetic generators animate: capsules (closed tubes with rounded caps),
// geodesic spheres and rectangular grids, plus the helpers that size them to a vertex budget and
// fill a MeshSequence frame by frame.
//
// Contracts shared by every builder:
//  - No duplicate vertices, no degenerate triangles, every vertex referenced.
//  - Triangles are counter-clockwise seen from outside (closed shapes) or from +z (grids), so
//    normals computed with (b - a) × (c - a) point outwards / up.
//  - Vertex and triangle order depend only on the builder's integer parameters, never on the seed.
#pragma once

#include <functional>

#include "dmc/sequence.h"

namespace dmc::synth {

// A static triangle mesh in double precision.
struct RestMesh {
  FramePositionsD positions;
  Triangles triangles;
  int vertex_count() const { return static_cast<int>(positions.rows()); }
};

// Sampling of a capsule: `segments` vertices around each ring, `rings` rings between the poles.
struct CapsuleLayout {
  int segments = 0;
  int body_intervals = 0;  // ring intervals along the cylindrical body (0 for a sphere)
  int cap_rings = 0;       // rings per hemispherical cap, excluding the equator and the pole
  int ring_count() const { return 2 * cap_rings + body_intervals + 1; }
  int vertex_count() const { return ring_count() * segments + 2; }
};

// Chooses a capsule sampling whose edges are about `spacing` long both around and along the
// axis, with at least `min_segments` vertices per ring.
CapsuleLayout LayoutCapsule(double radius, double length, double spacing, int min_segments = 6);

// A closed capsule around the +z axis: a cylinder of `radius` from z = 0 to z = `length` with a
// hemisphere on each end (poles at z = -radius and z = length + radius). Genus 0, Euler
// characteristic 2. Vertex 0 is the bottom pole, then the rings bottom to top (ring vertex j at
// azimuth 2πj/segments, starting on +x), then the top pole. `length` may be 0 (a sphere).
RestMesh BuildCapsule(double radius, double length, const CapsuleLayout& layout);

// A geodesic sphere: the icosahedron with each face split into frequency² triangles, projected
// on the unit sphere. V = 10·frequency² + 2, T = 20·frequency². frequency ≥ 1.
RestMesh BuildGeodesicSphere(int frequency);

// A `columns` × `rows` vertex grid on [0, width] × [0, height] in the z = 0 plane, row-major
// (vertex = row * columns + column), two triangles per cell with the diagonals alternating in a
// checkerboard so the mesh has no preferred shear direction. columns, rows ≥ 2.
RestMesh BuildGrid(int columns, int rows, double width, double height);

// Finds the sampling scale whose vertex count is closest to `target`: starts at `initial` and
// rescales by sqrt(count / target) a few times (counts grow like 1 / scale²), keeping the best.
double FitSpacing(const std::function<int(double spacing)>& count_for_spacing, int target,
                  double initial);

// Frame time in seconds: every generator animates at kFrameRate, frame f at time f / kFrameRate,
// so a shorter sequence is a prefix of a longer one with the same seed.
inline constexpr double kFrameRate = 30.0;

// Creates a sequence with `mesh`'s connectivity and fills frame f with pose(time(f), out), where
// `out` holds the frame's V positions in double precision (stored as float32).
MeshSequence AnimateFrames(const RestMesh& mesh, int frames, std::string name,
                           const std::function<void(double time, FramePositionsD& out)>& pose);

}  // namespace dmc::synth

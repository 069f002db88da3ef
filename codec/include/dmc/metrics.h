// Distortion metrics between an ORIGINAL mesh sequence A and a DISTORTED sequence A′ that share
// connectivity: the Karni–Gotsman error (KG), the spatio-temporal edge difference (STED, Váša &
// Skala 2011, with the constants of the authors' reference tool), the RMSE relative to the
// bounding-box diagonal and the maximum vertex error. The definitions are those of
// ../shared/docs/metrics.md, followed to the letter; every value is computed in double precision
// from the float32 positions.
//
// Definitions, in short (A is always the first argument, the ORIGINAL):
//  - KG = 100 · ‖A − A′‖_F / ‖A − E(A)‖_F, where E(A) replaces each position of frame f by the
//    centroid of frame f of A.
//  - Edges are the unique undirected edges of the triangle list (MeshTopology::edges).
//  - STED_s: for frame f and edge e, l(e) and l′(e) are its lengths in A and A′ and
//    ed(e) = (l(e) − l′(e)) / l(e). The neighbourhood N(v) of width w is every edge with at
//    least one endpoint within w one-ring steps of v (w = 0: the edges incident to v). Per vertex,
//    avg(v) = Σ l·ed / Σ l and dev(v) = sqrt(Σ_{l>0} l·(ed − avg)² / Σ l) over N(v);
//    STED_s = Σ_f Σ_v dev(v) / (V·F). A vertex whose avg is NaN — some edge of N(v) has zero length
//    in A in that frame (0·ed is then NaN), or N(v) is empty (an isolated vertex) — contributes 0
//    but still counts in the V·F denominator.
//  - STED_t: D is the diameter of frame 0 of A (largest distance between two of its vertices).
//    For f = 1..F−1, te(f,v) = sqrt(‖(p(f,v) − p(f−1,v)) / D‖² + dt²) on A, te′ likewise on A′
//    (still divided by A's D). s̄(f,v) is the mean of te(g,v) (of A) over
//    g ∈ [max(1, f−s+1), min(F−1, f+s)], and STED_t = Σ_{f≥1} Σ_v |te′ − te| / s̄ / (V·(F−1));
//    STED_t = 0 when F = 1.
//  - STED = sqrt(STED_s² + c²·STED_t²).
//  - rmse_rel = sqrt(Σ_{f,v} ‖p − p′‖² / (F·V)) / (bounding-box diagonal of A over all frames):
//    the root mean square of the per-vertex Euclidean error. max_error = max_{f,v} ‖p − p′‖, in
//    the model's units.
//
// STED is not symmetric: the ORIGINAL defines the edge lengths l, the diameter D and the local
// speed s̄. Swapping the arguments measures something else.
//
// Errors (never a number for bad input):
//  - kMismatch: different frame counts, vertex counts or triangle lists (CheckComparable).
//  - kInvalidSequence: either sequence fails ValidateSequence (no frames, an index out of range,
//    a non-finite coordinate, …), or the original is so degenerate that a metric is undefined:
//    every frame of A is a single point (KG's denominator is 0), or F > 1 and frame 0 of A is a
//    single point (D = 0).
//  - kInvalidArgument: StedOptions out of range (see ValidateStedOptions).
//
// Cost: KG is one pass over the positions. STED precomputes, once per original, the topology and
// the neighbourhood edge lists N(v) in CSR form; then the spatial part runs frame-parallel (TBB)
// with O(E) scratch per worker, and the temporal part runs vertex-block-parallel with a ring
// buffer of the last 2·s te values per vertex of a block. Memory beyond the two inputs is
// O(V + E + Σ_v |N(v)| + F) (Σ|N(v)| is about 30·V for w = 1 on a regular mesh; it grows quickly
// with w), never O(V·F). Results are deterministic: partial sums are combined in a fixed order
// regardless of the thread count. Measured (tests/bench/bench_metrics.cpp, 10k vertices × 150
// frames): STED about 185 ms of CPU in all, i.e. about 0.1 s on 2 idle cores; KG about 30 ms.
#pragma once

#include <memory>

#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc {

// Parameters of STED. The defaults are those of the authors' reference tool.
struct StedOptions {
  int width = 1;        // w: neighbourhood width in one-ring steps; >= 0
  double dt = 0.0003;   // frame distance added to every temporal edge length; finite, >= 0
  int window = 5;       // s: speed window half-width in frames; >= 1
  double c = 9.144e-5;  // weight of STED_t in the combined STED; finite, >= 0
};

// OK, or kInvalidArgument naming the first field out of range: width < 0, window < 1, dt or c
// negative or not finite.
//
// dt = 0 is allowed. Then a vertex at rest in A over its whole speed window has s̄ = 0; its term
// |te′ − te| / s̄ is taken as 0 when it is at rest in A′ too (0/0) and is +infinity otherwise, so
// STED_t and STED become +infinity.
Status ValidateStedOptions(const StedOptions& options);

// The three STED values.
struct StedResult {
  double sted = 0.0;    // sqrt(sted_s² + c²·sted_t²)
  double sted_s = 0.0;  // spatial part
  double sted_t = 0.0;  // temporal part (0 when F = 1)
};

// Everything `dmc metrics` reports (JSON keys are the field names).
struct DistortionReport {
  double kg = 0.0;
  double sted = 0.0;
  double sted_s = 0.0;
  double sted_t = 0.0;
  double rmse_rel = 0.0;   // RMSE of the per-vertex error / bounding-box diagonal of A
  double max_error = 0.0;  // largest per-vertex Euclidean error, model units
  int frames = 0;
  int vertices = 0;
};

// Largest Euclidean distance between two rows of `points` (0 for fewer than two points), computed
// in double; coordinates must be finite. The result is exactly the brute-force maximum over all
// pairs of sqrt(dx·dx + dy·dy + dz·dz), with d the difference of the double-converted coordinates.
//
// Algorithm: a strong lower bound first (the extreme points along 7 directions, refined by a few
// farthest-point steps), then a depth-first branch-and-bound over pairs of nodes of a lazily built
// kd-tree. Each node bounds its points by an axis-aligned box and by an oriented box in their
// principal frame (thin on curved surfaces); either gives an upper bound on the distance of any
// pair the two nodes hold, and a node pair is dropped as soon as a bound cannot beat the best
// distance found. The bounds are evaluated so that rounding can only loosen them (see
// src/metrics/diameter.cpp), so pruning never drops the true maximum. Elongated shapes (bodies,
// animals) touch a few hundred nodes: about 20 ms for 200k points, mostly the two linear passes.
// Points evenly spread on a perfect sphere are the worst case, about 0.7 s for 200k points.
double PointSetDiameter(const Eigen::Ref<const FramePositions>& points);

// KG error of `distorted` against `original`. Errors as listed at the top.
StatusOr<double> KgError(const MeshSequence& original, const MeshSequence& distorted);

// STED of `distorted` against `original` (which defines the lengths, D and the local speed).
StatusOr<StedResult> Sted(const MeshSequence& original, const MeshSequence& distorted,
                          const StedOptions& options = {});

// KG, STED and the vertex-error statistics in one call.
StatusOr<DistortionReport> MeasureDistortion(const MeshSequence& original,
                                             const MeshSequence& distorted,
                                             const StedOptions& options = {});

// Measures many distorted versions of one original (the encoder's closed loop, rate sweeps)
// without redoing the work that depends on the original only: validation, topology,
// neighbourhood lists, the diameter D, KG's denominator and the bounding-box diagonal.
//
// Lifetime: the meter keeps a pointer to `original`; the original must outlive the meter (and
// all its copies) and must not be modified meanwhile. Copies are cheap and share the
// precomputed data; Measure is const and safe to call from several threads at once.
class DistortionMeter {
 public:
  // Validates `original` and `options` and precomputes. Errors as listed at the top.
  static StatusOr<DistortionMeter> Create(const MeshSequence& original,
                                          const StedOptions& options = {});

  // Same result as MeasureDistortion(original, distorted, options). Fails with kMismatch or
  // kInvalidSequence when `distorted` is not comparable with the original or not valid.
  StatusOr<DistortionReport> Measure(const MeshSequence& distorted) const;

  const StedOptions& options() const;
  // Diameter D of frame 0 of the original.
  double diameter() const;

 private:
  struct State;
  explicit DistortionMeter(std::shared_ptr<const State> state) : state_(std::move(state)) {}
  std::shared_ptr<const State> state_;
};

}  // namespace dmc

// What building an operator takes besides the mesh: the options of every operator family and the
// source of the data-dependent ones (shared by dmc/ddl_fit.h and dmc/operator_registry.h; encoder
// and processing side, never the decoder's).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "dmc/operator_formulas.h"
#include "dmc/sequence.h"
#include "dmc/sparse_solvers.h"

namespace dmc {

// Reference operator of the DDL Tikhonov term.
enum class DdlReference : uint8_t { kTutte, kCotan };

struct DdlOptions {
  // Tikhonov weight μ ≥ 0, dimensionless. The fit minimises
  //   Σ_i ‖Σ_j w_ij (c_j − c_i)‖² + μ·s·Σ_{i→j} (w_ij − ref_ij)²
  // over directed edges, with s the mean of ‖c_j − c_i‖² over directed edges, so μ means the same
  // thing whatever the data's scale or rank: μ = 1 makes a unit weight deviation cost as much as
  // one typical squared edge residual. codec-notes found μ ≈ 1e-2..3e-2 toward Tutte to trade
  // a slightly larger residual for a much better conditioned normal matrix.
  double mu = 0.0;
  DdlReference reference = DdlReference::kTutte;
  // Always added on top of μ (same form): makes the problem strictly convex when the data do not
  // determine every weight (static or planar data, low rank), picking the solution nearest the
  // reference. Small enough not to move a well-determined fit measurably.
  double min_mu = 1e-9;
};

// Where an operator's inputs come from. Geometric operators use `reference_frame`; DDL operators
// use `trajectories` (V×r: one row per vertex; positions of all frames, PCA coefficients, or a
// single frame) and `reference_frame` only for a cotangent Tikhonov reference.
struct OperatorSource {
  std::optional<FramePositionsD> reference_frame;
  std::optional<Eigen::MatrixXd> trajectories;
};

// Options of the spacetime row (the full set is dmc/spacetime.h's SpacetimeOptions).
struct SpacetimeOperatorOptions {
  double alpha = 1.0;       // time weight α > 0 of the 4D metric diag(α, 1, 1, 1)
  double frame_rate = 0.0;  // frame k sits at time k / frame_rate; ≤ 0: at time k
};

// Options of the bspline row (the full set is dmc/bspline.h's BsplineOptions).
struct BsplineOperatorOptions {
  int depth = 0;  // octree depth in [1, 10]; 0 picks the depth whose voxel is about one mean
                  // edge long (AutomaticBsplineDepth, in [2, 7])
};

struct OperatorOptions {
  GeometricOptions geometric;
  DdlOptions ddl;
  SolverOptions solver;  // backend of the symmetric DDL fit's sparse factorisations
  SpacetimeOperatorOptions spacetime;
  BsplineOperatorOptions bspline;
  // BuildOperator refuses (kUnsupported, naming the operator's domain) to build an operator whose
  // domain is not kVertex unless this is set, so code written for V×V matrices gets a clear error
  // instead of a matrix of another size. Callers that read LaplaceOperator::domain set it.
  bool allow_any_domain = false;
};

}  // namespace dmc

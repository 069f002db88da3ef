// The operator registry: every operator dmc can build, by name or wire ID, from one table
// (encoder and processing side only; the decoder rebuilds operators with RebuildOperator in
// dmc/operator_formulas.h).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string_view>

#include "dmc/laplace_operator.h"
#include "dmc/operator_options.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "dmc/topology.h"
#include "dmc/wire_ids.h"

namespace dmc {

// One frame: reference frame = the frame, trajectories = its V×3 positions.
OperatorSource SourceFromFrame(const FramePositionsD& positions);
// A whole sequence: reference frame = frame `reference_frame_index`, or the mean frame when it
// is negative; trajectories = all frames' positions, V×3F with column 3f + axis.
OperatorSource SourceFromSequence(const MeshSequence& sequence, int reference_frame_index = -1);
// Reduced trajectories (e.g. PCA coefficients, V×r); add a reference frame for geometric ones.
OperatorSource SourceFromTrajectories(Eigen::MatrixXd trajectories);

using OperatorFactory = StatusOr<LaplaceOperator> (*)(const MeshTopology&, const OperatorSource&,
                                                      const OperatorOptions&);

// One row of the registry table.
struct OperatorInfo {
  std::string_view name;              // stable, lower case: "cotan-area"
  std::optional<OperatorId> wire_id;  // set for operators a decoder can rebuild (kVertex only)
  std::string_view description;
  bool needs_geometry = false;      // uses OperatorSource::reference_frame
  bool needs_trajectories = false;  // uses OperatorSource::trajectories
  bool symmetric = false;
  bool unit_sum = false;
  OperatorFactory factory = nullptr;
  OperatorDomain domain = OperatorDomain::kVertex;  // of every operator this row builds
};

// "vertex", "spacetime" or "element".
std::string_view OperatorDomainName(OperatorDomain domain);

// The table, in a fixed order. Adding an operator is one factory plus one row here.
std::span<const OperatorInfo> OperatorRegistry();
// Lookups; unknown → kNotFound whose message lists every name (or ID) that exists.
StatusOr<const OperatorInfo*> FindOperator(std::string_view name);
StatusOr<const OperatorInfo*> FindOperator(OperatorId id);
// Looks up `name` and builds it. Missing inputs → kInvalidArgument naming what is needed; a
// non-vertex domain without options.allow_any_domain → kUnsupported.
//
// The two rows without wire ID and their inputs:
//   spacetime  kSpacetime, from OperatorSource::trajectories read as F frames (V×3F, column
//              3k + axis: SourceFromSequence), options.spacetime. matrix = the DEC stiffness W
//              (symmetric, block tridiagonal, F·(V + 2E) + 2·V·(F − 1) nonzeros), mass = ⋆0, so
//              the paper's symmetrised Δ = M^{−1/2}·W·M^{−1/2} and unsymmetrised Δu = M⁻¹·W.
//              Needs F ≥ 2 frames.
//   bspline    kElement, from OperatorSource::reference_frame and options.bspline: matrix = the
//              element stiffness L (N×N, symmetric, L·1 = 0), mass_matrix = D, evaluation = the
//              V×N element values at the vertices.
// Both recover the triangles from the topology's edge/opposite table, so triangles beyond the
// second on a non-manifold edge are not seen.
StatusOr<LaplaceOperator> BuildOperator(std::string_view name, const MeshTopology& topology,
                                        const OperatorSource& source,
                                        const OperatorOptions& options = {});

}  // namespace dmc

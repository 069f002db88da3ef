// The operator registry: one table row per operator, name ↔ wire ID ↔ factory. Adding an
// operator is its builder (one file) plus one row in kRegistry.
#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

#include "dmc/bspline.h"
#include "dmc/operators.h"
#include "dmc/pca.h"
#include "dmc/spacetime.h"

namespace dmc {
namespace {

Status RequireFrame(const OperatorSource& source, std::string_view name) {
  if (!source.reference_frame.has_value()) {
    return InvalidArgumentError(fmt::format(
        "operator {} is geometric: give a frame or a sequence (reference frame) as its source",
        name));
  }
  return Status::Ok();
}

// Adapters from the uniform factory signature to the operator builders.
StatusOr<LaplaceOperator> MakeKirchhoff(const MeshTopology& topology, const OperatorSource&,
                                        const OperatorOptions&) {
  return BuildKirchhoff(topology);
}
StatusOr<LaplaceOperator> MakeTutte(const MeshTopology& topology, const OperatorSource&,
                                    const OperatorOptions&) {
  return BuildTutte(topology);
}
StatusOr<LaplaceOperator> MakeCotan(const MeshTopology& topology, const OperatorSource& source,
                                    const OperatorOptions& options) {
  DMC_RETURN_IF_ERROR(RequireFrame(source, "cotan"));
  return BuildCotan(topology, *source.reference_frame, options.geometric);
}
StatusOr<LaplaceOperator> MakeCotanArea(const MeshTopology& topology, const OperatorSource& source,
                                        const OperatorOptions& options) {
  DMC_RETURN_IF_ERROR(RequireFrame(source, "cotan-area"));
  return BuildCotanArea(topology, *source.reference_frame, options.geometric);
}
StatusOr<LaplaceOperator> MakeCotanSym(const MeshTopology& topology, const OperatorSource& source,
                                       const OperatorOptions& options) {
  DMC_RETURN_IF_ERROR(RequireFrame(source, "cotan-sym"));
  return BuildCotanSym(topology, *source.reference_frame, options.geometric);
}
StatusOr<LaplaceOperator> MakeMeanValue(const MeshTopology& topology, const OperatorSource& source,
                                        const OperatorOptions& options) {
  DMC_RETURN_IF_ERROR(RequireFrame(source, "mean-value"));
  return BuildMeanValue(topology, *source.reference_frame, options.geometric);
}

// The 3D+t DEC operator of the frames in `trajectories` (V×3F). Its matrix is the stiffness W and
// its mass ⋆0, the same split as cotan-sym's (weights, vertex areas), so every row sums to zero
// and the paper's symmetrised Δ is M^{−1/2}·W·M^{−1/2} (SymmetrisedSpacetimeLaplacian).
StatusOr<LaplaceOperator> MakeSpacetime(const MeshTopology& topology, const OperatorSource& source,
                                        const OperatorOptions& options) {
  if (!source.trajectories.has_value()) {
    return InvalidArgumentError(
        "operator spacetime needs the positions of every frame (V x 3F trajectories): give a "
        "sequence as its source");
  }
  const Eigen::MatrixXd& trajectories = *source.trajectories;
  if (trajectories.rows() != topology.vertex_count || trajectories.cols() % 3 != 0) {
    return InvalidArgumentError(fmt::format(
        "operator spacetime reads its trajectories as frames of V x 3 positions; got {} x {} for "
        "{} vertices",
        trajectories.rows(), trajectories.cols(), topology.vertex_count));
  }
  const int frame_count = static_cast<int>(trajectories.cols() / 3);
  if (frame_count < 2) {
    return InvalidArgumentError(
        fmt::format("operator spacetime needs at least 2 frames, got {}", frame_count));
  }
  std::vector<FramePositionsD> frames;
  frames.reserve(frame_count);
  for (int k = 0; k < frame_count; ++k) frames.emplace_back(trajectories.middleCols(3 * k, 3));
  SpacetimeOptions spacetime;
  spacetime.alpha = options.spacetime.alpha;
  if (options.spacetime.frame_rate > 0.0) {
    for (int k = 0; k < frame_count; ++k) {
      spacetime.frame_times.push_back(k / options.spacetime.frame_rate);
    }
  }
  spacetime.max_cotangent = options.geometric.max_cotangent;
  DMC_ASSIGN_OR_RETURN(
      SpacetimeLaplacian built,
      BuildSpacetimeLaplacian(topology, TrianglesFromTopology(topology), frames, spacetime));
  LaplaceOperator result;
  result.matrix = std::move(built.stiffness);
  result.mass = std::move(built.mass);
  result.symmetric = true;
  result.domain = OperatorDomain::kSpacetime;
  result.frame_count = frame_count;
  const SpacetimeStats& stats = built.geometry.stats;
  result.stats.clamped_cotangents = stats.clamped_cotangents;
  result.stats.short_spatial_edges = stats.short_spatial_edges;
  result.stats.empty_vertex_duals = stats.empty_vertex_duals;
  result.stats.isolated_vertices = topology.isolated_vertex_count;
  return result;
}

// The restricted B-spline element operator at one depth (no multigrid hierarchy: a registry
// caller wants the operator, BsplineMultigrid builds its own levels).
StatusOr<LaplaceOperator> MakeBspline(const MeshTopology& topology, const OperatorSource& source,
                                      const OperatorOptions& options) {
  DMC_RETURN_IF_ERROR(RequireFrame(source, "bspline"));
  const FramePositionsD& positions = *source.reference_frame;
  if (positions.rows() != topology.vertex_count) {
    return MismatchError(fmt::format("operator bspline: {} positions for a topology of {} vertices",
                                     positions.rows(), topology.vertex_count));
  }
  const Triangles triangles = TrianglesFromTopology(topology);
  BsplineOptions bspline;
  bspline.depth = options.bspline.depth > 0 ? options.bspline.depth
                                            : AutomaticBsplineDepth(triangles, positions);
  bspline.coarsest_depth = bspline.depth;
  DMC_ASSIGN_OR_RETURN(BsplineOperator built, BuildBsplineOperator(triangles, positions, bspline));
  BsplineLevel& finest = built.levels.back();
  LaplaceOperator result;
  result.matrix = std::move(finest.laplacian);
  result.mass_matrix = std::move(finest.mass);
  result.evaluation = std::move(built.evaluation);
  result.symmetric = true;
  result.domain = OperatorDomain::kElement;
  result.stats.isolated_vertices = topology.isolated_vertex_count;
  return result;
}

// name, wire ID, description, needs_geometry, needs_trajectories, symmetric, unit_sum, factory,
// domain (kVertex unless given). Only kVertex rows can carry a wire ID.
const OperatorInfo kRegistry[] = {
    {"kirchhoff", OperatorId::kKirchhoff, "graph Laplacian, w_ij = 1, diagonal −degree", false,
     false, true, false, MakeKirchhoff},
    {"tutte", OperatorId::kTutte, "uniform weights 1/deg(i), unit row sum", false, false, false,
     true, MakeTutte},
    {"cotan", OperatorId::kCotan, "cotangent weights scaled to unit row sum", true, false, false,
     true, MakeCotan},
    {"cotan-area", OperatorId::kCotanArea,
     "cotangent weights / mixed Voronoi area (mean-curvature normal)", true, false, false, false,
     MakeCotanArea},
    {"cotan-sym", OperatorId::kCotanSym, "symmetric cotangent weights (DEC), with mass matrix",
     true, false, true, false, MakeCotanSym},
    {"mean-value", OperatorId::kMeanValue, "Floater's mean value weights, unit row sum", true,
     false, false, true, MakeMeanValue},
    {"ddl", OperatorId::kDdl, "data-dependent Laplacian: symmetric weights fitted to trajectories",
     false, true, true, true, FitDdlSymmetric},
    {"ddl-asym", OperatorId::kDdlAsym,
     "data-dependent Laplacian: one fitted weight per directed edge", false, true, false, true,
     FitDdlAsymmetric},
    {"spacetime", std::nullopt,
     "3D+t DEC Laplacian of all frames (VF x VF stiffness W, mass = dual volumes; needs alpha)",
     false, true, true, false, MakeSpacetime, OperatorDomain::kSpacetime},
    {"bspline", std::nullopt,
     "restricted B-spline Laplace-Beltrami on octree elements (N x N, mass matrix, V x N "
     "evaluation; depth)",
     true, false, true, false, MakeBspline, OperatorDomain::kElement},
};

std::string KnownNames() {
  std::string list;
  for (const OperatorInfo& info : kRegistry) {
    if (!list.empty()) list += ", ";
    list += info.name;
  }
  return list;
}

std::string KnownIds() {
  std::string list;
  for (const OperatorInfo& info : kRegistry) {
    if (!info.wire_id) continue;
    if (!list.empty()) list += ", ";
    list += fmt::format("{} ({})", static_cast<int>(*info.wire_id), info.name);
  }
  return list;
}

}  // namespace

std::string_view OperatorDomainName(OperatorDomain domain) {
  switch (domain) {
    case OperatorDomain::kVertex:
      return "vertex";
    case OperatorDomain::kSpacetime:
      return "spacetime";
    case OperatorDomain::kElement:
      return "element";
  }
  return "unknown";
}

std::span<const OperatorInfo> OperatorRegistry() { return kRegistry; }

StatusOr<const OperatorInfo*> FindOperator(std::string_view name) {
  for (const OperatorInfo& info : kRegistry) {
    if (info.name == name) return &info;
  }
  return NotFoundError(
      fmt::format("unknown operator '{}'; known operators: {}", name, KnownNames()));
}

StatusOr<const OperatorInfo*> FindOperator(OperatorId id) {
  for (const OperatorInfo& info : kRegistry) {
    if (info.wire_id == id) return &info;
  }
  return NotFoundError(
      fmt::format("unknown operator ID {}; known IDs: {}", static_cast<int>(id), KnownIds()));
}

StatusOr<LaplaceOperator> BuildOperator(std::string_view name, const MeshTopology& topology,
                                        const OperatorSource& source,
                                        const OperatorOptions& options) {
  DMC_ASSIGN_OR_RETURN(const OperatorInfo* info, FindOperator(name));
  if (info->domain != OperatorDomain::kVertex && !options.allow_any_domain) {
    return UnsupportedError(fmt::format(
        "operator {} acts on the {} domain ({}), not on the mesh's vertices; this use needs a "
        "per-vertex (V x V) operator",
        info->name, OperatorDomainName(info->domain),
        info->domain == OperatorDomain::kSpacetime ? "a VF x VF matrix over every frame's vertices"
                                                   : "an N x N matrix over B-spline elements"));
  }
  DMC_ASSIGN_OR_RETURN(LaplaceOperator result, info->factory(topology, source, options));
  result.name = std::string(info->name);
  return result;
}

OperatorSource SourceFromFrame(const FramePositionsD& positions) {
  OperatorSource source;
  source.reference_frame = positions;
  source.trajectories = Eigen::MatrixXd(positions);
  return source;
}

OperatorSource SourceFromSequence(const MeshSequence& sequence, int reference_frame_index) {
  OperatorSource source;
  source.reference_frame =
      reference_frame_index >= 0 && reference_frame_index < sequence.frame_count()
          ? sequence.frame_d(reference_frame_index)
          : MeanFrame(sequence);
  source.trajectories = TrajectoryMatrix(sequence);
  return source;
}

OperatorSource SourceFromTrajectories(Eigen::MatrixXd trajectories) {
  OperatorSource source;
  source.trajectories = std::move(trajectories);
  return source;
}

}  // namespace dmc

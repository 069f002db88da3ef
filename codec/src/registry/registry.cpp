// The operator registry: one table row per operator, name → factory, with its wire ID from
// kOperatorTraits (dmc/operator_traits.h). Adding an operator is its builder (one file), its
// traits row, and one row in kRegistry.
#include <fmt/format.h>

#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "core/allocation_guard.h"
#include "dmc/bspline.h"
#include "dmc/operator_traits.h"
#include "dmc/operators.h"
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

// A row of kRegistry, its wire ID from the name's kOperatorTraits row (RegistryMatchesTraits below
// checks that every name has one). Only kVertex rows can carry a wire ID.
consteval OperatorInfo Row(std::string_view name, std::string_view description, bool needs_geometry,
                           bool needs_trajectories, bool symmetric, bool unit_sum,
                           OperatorFactory factory,
                           OperatorDomain domain = OperatorDomain::kVertex) {
  // A loop rather than FindOperatorTraits: GCC's sanitizer builds do not take a comparison of a
  // global's address with nullptr as a constant expression.
  std::optional<OperatorId> wire_id;
  for (const OperatorTraits& traits : kOperatorTraits) {
    if (traits.name == name && traits.id != OperatorId::kInvalid) wire_id = traits.id;
  }
  return {name,      wire_id,  description, needs_geometry, needs_trajectories,
          symmetric, unit_sum, factory,     domain};
}

// name, description, needs_geometry, needs_trajectories, symmetric, unit_sum, factory, domain.
constexpr OperatorInfo kRegistry[] = {
    Row("kirchhoff", "graph Laplacian, w_ij = 1, diagonal −degree", false, false, true, false,
        MakeKirchhoff),
    Row("tutte", "uniform weights 1/deg(i), unit row sum", false, false, false, true, MakeTutte),
    Row("cotan", "cotangent weights scaled to unit row sum", true, false, false, true, MakeCotan),
    Row("cotan-area", "cotangent weights / mixed Voronoi area (mean-curvature normal)", true, false,
        false, false, MakeCotanArea),
    Row("cotan-sym", "symmetric cotangent weights (DEC), with mass matrix", true, false, true,
        false, MakeCotanSym),
    Row("mean-value", "Floater's mean value weights, unit row sum", true, false, false, true,
        MakeMeanValue),
    Row("ddl", "data-dependent Laplacian: symmetric weights fitted to trajectories", false, true,
        true, true, FitDdlSymmetric),
    Row("ddl-asym", "data-dependent Laplacian: one fitted weight per directed edge", false, true,
        false, true, FitDdlAsymmetric),
    Row("spacetime",
        "3D+t DEC Laplacian of all frames (VF x VF stiffness W, mass = dual volumes; needs alpha)",
        false, true, true, false, MakeSpacetime, OperatorDomain::kSpacetime),
    Row("bspline",
        "restricted B-spline Laplace-Beltrami on octree elements (N x N, mass matrix, V x N "
        "evaluation; depth)",
        true, false, true, false, MakeBspline, OperatorDomain::kElement),
};

// The registry holds exactly the kOperatorTraits rows, and builds a geometric one from a frame.
consteval bool RegistryMatchesTraits() {
  if (std::size(kRegistry) != std::size(kOperatorTraits)) return false;
  for (const OperatorTraits& traits : kOperatorTraits) {
    int rows = 0;
    for (const OperatorInfo& info : kRegistry) {
      if (info.name != traits.name) continue;
      ++rows;
      if (traits.geometric() && !info.needs_geometry) return false;
    }
    if (rows != 1) return false;
  }
  return true;
}
static_assert(RegistryMatchesTraits(), "kRegistry must hold every kOperatorTraits row once");

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
  DMC_ASSIGN_OR_RETURN(
      LaplaceOperator result,
      core_internal::GuardAllocation(fmt::format("building the {} operator", info->name),
                                     [&] { return info->factory(topology, source, options); }));
  result.name = std::string(info->name);
  return result;
}

}  // namespace dmc

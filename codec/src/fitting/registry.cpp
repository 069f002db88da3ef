// The operator registry: one table row per operator, name ↔ wire ID ↔ factory. Adding an
// operator is its builder (one file) plus one row in kRegistry.
#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "dmc/operators.h"
#include "dmc/pca.h"

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

// name, wire ID, description, needs_geometry, needs_trajectories, symmetric, unit_sum, factory.
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

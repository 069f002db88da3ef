// spacetime-arap: as-rigid-as-possible editing of a key frame propagated over a temporal window
// through the 3D+t spacetime Laplacian (dmc/spacetime.h, SpacetimeArapEditor; the paper's §5.3).
//
// The selection's handles are moved in the key frame by its transform (or, with --key-mesh, the
// key frame is replaced by an edited mesh: every vertex but the fixed ones becomes a handle); its
// fixed vertices (the spatial boundary of the region of interest) keep their input positions in
// every frame of the window; the window's first and last frames are anchored too unless they are
// the sequence's ends or --free-window-ends is given. The method builds its own operator (the
// registry's V×V operators do not apply), so --operator is ignored. Precompute builds the
// spacetime operator of the window and factorises the system once; ApplySequence iterates.
#include <fmt/format.h>

#include <string>

#include "dmc/io.h"
#include "dmc/processing.h"
#include "dmc/spacetime.h"

namespace dmc {
namespace {

class PreparedSpacetimeArap final : public PreparedMethod {
 public:
  PreparedSpacetimeArap(SpacetimeArapEditor editor, Eigen::MatrixXd targets, int key_frame,
                        int vertex_count, int frame_count)
      : editor_(std::move(editor)),
        targets_(std::move(targets)),
        key_frame_(key_frame),
        vertex_count_(vertex_count),
        frame_count_(frame_count) {}

  // Edits the sequence the method was prepared for (its operator and factor depend on it).
  StatusOr<ProcessingResult> ApplySequence(const MeshSequence& sequence) const override {
    if (sequence.vertex_count() != vertex_count_ || sequence.frame_count() != frame_count_) {
      return MismatchError("spacetime-arap: the sequence differs from the one it was prepared for");
    }
    DMC_ASSIGN_OR_RETURN(SpacetimeArapResult edit, editor_.Solve(targets_));
    ProcessingResult result;
    result.sequence = std::move(edit.sequence);
    result.sequence.name = sequence.name;
    result.sequence.frame_rate = sequence.frame_rate;
    const int k = key_frame_;
    result.measurements = {
        {k, "window_first_frame", static_cast<double>(edit.first_frame)},
        {k, "window_last_frame", static_cast<double>(edit.last_frame)},
        {k, "iterations", static_cast<double>(edit.iterations)},
        {k, "converged", edit.converged ? 1.0 : 0.0},
        {k, "last_move", edit.last_move},
        {k, "initial_energy", edit.energies.front()},
        {k, "final_energy", edit.energies.back()},
        {k, "max_handle_error", edit.max_handle_error},
    };
    return result;
  }

 private:
  SpacetimeArapEditor editor_;
  Eigen::MatrixXd targets_;
  int key_frame_, vertex_count_, frame_count_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  const MeshSequence& sequence = context.sequence;
  const ParameterValues& p = context.parameters;
  SpacetimeArapOptions options;
  DMC_ASSIGN_OR_RETURN(options.key_frame, p.Integer("key-frame"));
  DMC_ASSIGN_OR_RETURN(options.alpha, p.Number("alpha"));
  DMC_ASSIGN_OR_RETURN(options.window, p.Integer("window"));
  DMC_ASSIGN_OR_RETURN(options.constraint_weight, p.Number("constraint-weight"));
  DMC_ASSIGN_OR_RETURN(options.tolerance, p.Number("tolerance"));
  DMC_ASSIGN_OR_RETURN(options.max_iterations, p.Integer("max-iterations"));
  DMC_ASSIGN_OR_RETURN(const bool free_ends, p.Flag("free-window-ends"));
  options.anchor_temporal_boundary = !free_ends;
  DMC_ASSIGN_OR_RETURN(const std::string dual, p.Text("spatial-dual"));
  if (dual == "barycentric") {
    options.spatial_dual = SpatialDual::kBarycentric;
  } else if (dual == "circumcentric") {
    options.spatial_dual = SpatialDual::kCircumcentric;
  } else {
    return InvalidArgumentError(
        fmt::format("--spatial-dual must be barycentric or circumcentric, got '{}'", dual));
  }
  DMC_ASSIGN_OR_RETURN(const std::string solver, p.Text("solver"));
  if (solver == "cholesky") {
    options.solver = SpacetimeSolverKind::kSparseCholesky;
  } else if (solver == "block-ldlt") {
    options.solver = SpacetimeSolverKind::kBlockLdlt;
  } else {
    return InvalidArgumentError(
        fmt::format("--solver must be cholesky or block-ldlt, got '{}'", solver));
  }
  if (options.key_frame < 0) options.key_frame += sequence.frame_count();  // -1 = the last

  SpacetimeArapConstraints constraints;
  constraints.fixed = context.selection.fixed;
  Eigen::MatrixXd targets;
  DMC_ASSIGN_OR_RETURN(const std::string key_mesh, p.Text("key-mesh"));
  if (options.key_frame < 0 || options.key_frame >= sequence.frame_count()) {
    return InvalidArgumentError(fmt::format("--key-frame {} outside the {}-frame input",
                                            options.key_frame, sequence.frame_count()));
  }
  if (!key_mesh.empty()) {
    StatusOr<MeshSequence> edited = ReadSequence(key_mesh);
    if (!edited.ok()) return edited.status().WithContext("spacetime-arap: --key-mesh");
    if (edited->vertex_count() != sequence.vertex_count() || edited->frame_count() < 1) {
      return MismatchError(fmt::format("spacetime-arap: --key-mesh has {} vertices, the input {}",
                                       edited->vertex_count(), sequence.vertex_count()));
    }
    std::vector<uint8_t> fixed(sequence.vertex_count(), 0);
    for (int32_t v : constraints.fixed) fixed[v] = 1;
    for (int v = 0; v < sequence.vertex_count(); ++v) {
      if (!fixed[v]) constraints.handles.push_back(v);
    }
    const FramePositionsD key = edited->frame_d(0);
    targets.resize(static_cast<Eigen::Index>(constraints.handles.size()), 3);
    for (size_t h = 0; h < constraints.handles.size(); ++h) {
      targets.row(static_cast<Eigen::Index>(h)) = key.row(constraints.handles[h]);
    }
  } else {
    if (context.selection.handles.empty()) {
      return InvalidArgumentError(
          "spacetime-arap needs handles in --selection (or an edited key frame in --key-mesh)");
    }
    constraints.handles = context.selection.handles;
    targets = TransformedHandlePositions(context.selection, sequence.frame_d(options.key_frame));
  }
  // The editor's messages already name the method.
  StatusOr<SpacetimeArapEditor> editor =
      SpacetimeArapEditor::Create(sequence, constraints, options);
  if (!editor.ok()) return editor.status();
  return std::unique_ptr<PreparedMethod>(
      new PreparedSpacetimeArap(std::move(editor).value(), std::move(targets), options.key_frame,
                                sequence.vertex_count(), sequence.frame_count()));
}

constexpr ParameterSpec kParameters[] = {
    {"key-frame", ParameterType::kInteger, "0", "the edited frame K; negative counts from the end"},
    {"alpha", ParameterType::kNumber, "1",
     "time weight of the 4D metric diag(alpha, 1, 1, 1): large keeps the edit in the key frame, "
     "small spreads it over the window"},
    {"window", ParameterType::kInteger, "2", "frames K-W .. K+W are edited (W >= 1)"},
    {"free-window-ends", ParameterType::kFlag, "false",
     "do not anchor the window's first and last frames (the edit then carries over the window)"},
    {"key-mesh", ParameterType::kText, "",
     "an edited key frame (mesh file with the input's vertices) replacing the handle transform"},
    {"constraint-weight", ParameterType::kNumber, "1000",
     "soft constraint weight relative to the mean diagonal of the spacetime stiffness"},
    {"tolerance", ParameterType::kNumber, "1e-5",
     "stop when the largest vertex move is below this fraction of the bounding-box diagonal"},
    {"max-iterations", ParameterType::kInteger, "100", "local/global iterations at most"},
    {"spatial-dual", ParameterType::kText, "barycentric",
     "spatial edge duals: barycentric (the paper) or circumcentric (cotangent weights)"},
    {"solver", ParameterType::kText, "cholesky",
     "cholesky (CHOLMOD) or block-ldlt (dense Schur complements, small meshes)"},
};

}  // namespace

MethodInfo SpacetimeArapMethod() {
  return {.name = "spacetime-arap",
          .description =
              "as-rigid-as-possible edit of a key frame spread over a temporal window "
              "by the 3D+t spacetime Laplacian (alpha balances time and space)",
          .scope = MethodScope::kWholeSequence,
          .needs_operator = false,
          .needs_selection = false,
          .vertex_scalar = {},
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc

// Running a registered method: one topology, one operator and one precompute per run, then
// Apply / ApplySequence as often as needed.
#include <fmt/format.h>

#include <algorithm>

#include "core/allocation_guard.h"
#include "dmc/processing.h"

namespace dmc {

StatusOr<FrameOutput> PreparedMethod::Apply(const FramePositionsD&, int,
                                            const FrameConstraints*) const {
  return UnsupportedError("this method processes whole sequences only (use ApplySequence)");
}

StatusOr<ProcessingResult> PreparedMethod::ApplySequence(const MeshSequence& sequence) const {
  ProcessingResult result;
  result.sequence = MeshSequence(sequence.vertex_count(), sequence.triangles(), 0);
  result.sequence.name = sequence.name;
  result.sequence.frame_rate = sequence.frame_rate;
  for (int f = 0; f < sequence.frame_count(); ++f) {
    StatusOr<FrameOutput> output = Apply(sequence.frame_d(f), f);
    if (!output.ok()) return output.status().WithContext(fmt::format("frame {}", f));
    DMC_RETURN_IF_ERROR(result.sequence.AppendFrame(output->positions.cast<float>()));
    if (!scalar_name_.empty()) result.vertex_scalars.push_back(std::move(output->vertex_scalar));
    for (Measurement& measurement : output->measurements) {
      result.measurements.push_back(std::move(measurement));
    }
  }
  if (!scalar_name_.empty()) result.scalar_name = scalar_name_;
  return result;
}

namespace {

StatusOr<PreparedRun> PrepareUnguarded(std::string_view method, const MeshSequence& sequence,
                                       const RunOptions& options) {
  PreparedRun run;
  DMC_ASSIGN_OR_RETURN(run.method, FindMethod(method));
  DMC_RETURN_IF_ERROR(ValidateSequence(sequence));
  DMC_ASSIGN_OR_RETURN(run.parameters,
                       ParameterValues::Create(run.method->parameters, options.parameters));
  run.selection = options.selection;
  DMC_RETURN_IF_ERROR(ValidateSelection(run.selection, sequence.vertex_count()));
  if (run.method->needs_selection && run.selection.handles.empty()) {
    return InvalidArgumentError(
        fmt::format("method {} needs a selection with at least one handle", run.method->name));
  }
  if (options.operator_frame >= sequence.frame_count()) {
    return InvalidArgumentError(fmt::format("operator frame {} is beyond the last frame {}",
                                            options.operator_frame, sequence.frame_count() - 1));
  }
  run.topology = BuildTopology(sequence.triangles(), sequence.vertex_count());
  const OperatorSource source = SourceFromSequence(sequence, options.operator_frame);
  if (run.method->needs_operator) {
    DMC_ASSIGN_OR_RETURN(run.laplace, BuildOperator(options.operator_name, run.topology, source,
                                                    options.operator_options));
  } else {
    // Still reject a typo in --operator up front, even if the method builds its own.
    DMC_RETURN_IF_ERROR(FindOperator(options.operator_name).status());
  }
  const ProcessingContext context{
      .sequence = sequence,
      .topology = run.topology,
      .laplace = run.laplace ? &*run.laplace : nullptr,
      .reference_frame = *source.reference_frame,
      .selection = run.selection,
      .parameters = run.parameters,
      .operator_name = options.operator_name,
      .operator_options = options.operator_options,
  };
  DMC_ASSIGN_OR_RETURN(run.prepared, run.method->precompute(context));
  return run;
}

}  // namespace

StatusOr<PreparedRun> Prepare(std::string_view method, const MeshSequence& sequence,
                              const RunOptions& options) {
  return core_internal::GuardAllocation(fmt::format("preparing {}", method), [&] {
    return PrepareUnguarded(method, sequence, options);
  });
}

namespace {

// No method returns positions that are not finite: a diverging iteration is an error.
Status CheckFinite(std::string_view method, const Eigen::Ref<const Eigen::MatrixXd>& positions,
                   int frame) {
  if (positions.allFinite()) return Status::Ok();
  return NumericalFailureError(fmt::format(
      "{} produced positions that are not finite in frame {}: it diverged (for smoothing, lower "
      "--lambda or use another operator)",
      method, frame));
}

}  // namespace

StatusOr<ProcessingResult> RunMethod(std::string_view method, const MeshSequence& sequence,
                                     const RunOptions& options) {
  DMC_ASSIGN_OR_RETURN(PreparedRun run, Prepare(method, sequence, options));
  DMC_ASSIGN_OR_RETURN(ProcessingResult result,
                       core_internal::GuardAllocation(fmt::format("running {}", method), [&] {
                         return run.prepared->ApplySequence(sequence);
                       }));
  for (int f = 0; f < result.sequence.frame_count(); ++f) {
    DMC_RETURN_IF_ERROR(CheckFinite(method, result.sequence.frame_d(f), f));
  }
  return result;
}

StatusOr<FrameOutput> RunMethodOnMesh(std::string_view method, const Triangles& triangles,
                                      const FramePositionsD& positions, const RunOptions& options) {
  MeshSequence mesh(static_cast<int>(positions.rows()), triangles, 0);
  DMC_RETURN_IF_ERROR(mesh.AppendFrame(positions.cast<float>()));
  DMC_ASSIGN_OR_RETURN(PreparedRun run, Prepare(method, mesh, options));
  if (run.method->scope == MethodScope::kWholeSequence) {
    return UnsupportedError(
        fmt::format("method {} processes whole sequences; use RunMethod", run.method->name));
  }
  DMC_ASSIGN_OR_RETURN(FrameOutput output,
                       core_internal::GuardAllocation(fmt::format("running {}", method), [&] {
                         return run.prepared->Apply(positions, 0);
                       }));
  DMC_RETURN_IF_ERROR(CheckFinite(method, output.positions, 0));
  return output;
}

}  // namespace dmc

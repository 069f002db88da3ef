// Input checks, option checks, DistortionMeter and MeasureDistortion; see dmc/metrics.h.
#include <cmath>
#include <memory>
#include <string>

#include "core/allocation_guard.h"
#include "dmc/metrics.h"
#include "metrics/metrics_internal.h"

namespace dmc {

namespace metrics_internal {

Status CheckInputs(const MeshSequence& original, const MeshSequence& distorted) {
  // Comparability first: two sequences of different shapes are a mismatch even when each is
  // also invalid on its own.
  DMC_RETURN_IF_ERROR(CheckComparable(original, distorted).WithContext("original vs distorted"));
  DMC_RETURN_IF_ERROR(ValidateSequence(original).WithContext("original"));
  DMC_RETURN_IF_ERROR(ValidateSequence(distorted).WithContext("distorted"));
  return Status::Ok();
}

DistortionReport AssembleReport(const StedResult& sted, const VertexErrorSums& errors,
                                const KgReference& kg, int frame_count, int vertex_count) {
  const double value_count = static_cast<double>(frame_count) * static_cast<double>(vertex_count);
  DistortionReport report;
  report.kg = KgFromSums(errors.squared_sum, kg.centroid_deviation_squared);
  report.sted = sted.sted;
  report.sted_s = sted.sted_s;
  report.sted_t = sted.sted_t;
  report.rmse_rel = std::sqrt(errors.squared_sum / value_count) / kg.bounding_box_diagonal;
  report.max_error = std::sqrt(errors.largest_squared);
  report.frames = frame_count;
  report.vertices = vertex_count;
  return report;
}

}  // namespace metrics_internal

Status ValidateStedOptions(const StedOptions& options) {
  if (options.width < 0) {
    return InvalidArgumentError("STED width must be >= 0, got " + std::to_string(options.width));
  }
  if (options.window < 1) {
    return InvalidArgumentError("STED window must be >= 1, got " + std::to_string(options.window));
  }
  if (!std::isfinite(options.dt) || options.dt < 0.0) {
    return InvalidArgumentError("STED dt must be finite and >= 0, got " +
                                std::to_string(options.dt));
  }
  if (!std::isfinite(options.c) || options.c < 0.0) {
    return InvalidArgumentError("STED c must be finite and >= 0, got " + std::to_string(options.c));
  }
  return Status::Ok();
}

struct DistortionMeter::State {
  const MeshSequence* original = nullptr;
  metrics_internal::StedReference sted;
  metrics_internal::KgReference kg;
};

StatusOr<DistortionMeter> DistortionMeter::Create(const MeshSequence& original,
                                                  const StedOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateStedOptions(options));
  DMC_RETURN_IF_ERROR(ValidateSequence(original).WithContext("original"));
  auto state = std::make_shared<State>();
  state->original = &original;
  DMC_ASSIGN_OR_RETURN(state->sted, metrics_internal::PrepareSted(original, options));
  DMC_ASSIGN_OR_RETURN(state->kg, metrics_internal::PrepareKg(original));
  return DistortionMeter(std::move(state));
}

StatusOr<DistortionReport> DistortionMeter::Measure(const MeshSequence& distorted) const {
  const MeshSequence& original = *state_->original;
  DMC_RETURN_IF_ERROR(CheckComparable(original, distorted).WithContext("original vs distorted"));
  DMC_RETURN_IF_ERROR(ValidateSequence(distorted).WithContext("distorted"));

  const StedResult sted = metrics_internal::ComputeSted(state_->sted, original, distorted);
  metrics_internal::VertexErrorSums errors;
  metrics_internal::AccumulateVertexErrors(metrics_internal::WholeSequence(original),
                                           metrics_internal::WholeSequence(distorted), 0,
                                           original.frame_count(), errors);
  return metrics_internal::AssembleReport(sted, errors, state_->kg, original.frame_count(),
                                          original.vertex_count());
}

const StedOptions& DistortionMeter::options() const { return state_->sted.options; }

double DistortionMeter::diameter() const { return state_->sted.diameter; }

StatusOr<DistortionReport> MeasureDistortion(const MeshSequence& original,
                                             const MeshSequence& distorted,
                                             const StedOptions& options) {
  DMC_RETURN_IF_ERROR(ValidateStedOptions(options));
  // Mismatches are reported before the (longer) preparation of the original.
  DMC_RETURN_IF_ERROR(CheckComparable(original, distorted).WithContext("original vs distorted"));
  return core_internal::GuardAllocation(
      "measuring the distortion", [&]() -> StatusOr<DistortionReport> {
        DMC_ASSIGN_OR_RETURN(const DistortionMeter meter,
                             DistortionMeter::Create(original, options));
        return meter.Measure(distorted);
      });
}

}  // namespace dmc

// Decoder-side dispatch from a wire ID to the builder of that operator.
#include <string>

#include "dmc/operator_traits.h"
#include "dmc/operators.h"

namespace dmc {
namespace {

std::string KnownIds() {
  std::string list;
  // Names come from the frozen table in wire_ids.h; 0 ("invalid") is never a real operator.
  for (const auto& entry : kOperatorIdNames) {
    if (entry.value == OperatorId::kInvalid) continue;
    if (!list.empty()) list += ", ";
    list += std::to_string(static_cast<int>(entry.value)) + " (" + std::string(entry.name) + ")";
  }
  return list;
}

}  // namespace

std::string_view OperatorIdName(OperatorId id) {
  return id == OperatorId::kInvalid ? std::string_view() : WireNameOf(kOperatorIdNames, id);
}

StatusOr<LaplaceOperator> RebuildOperator(OperatorId id, const MeshTopology& topology,
                                          const FramePositionsD* reference_frame,
                                          const OperatorWeights* weights) {
  const std::string_view name = OperatorIdName(id);
  if (name.empty()) {
    return NotFoundError("unknown operator ID " + std::to_string(static_cast<int>(id)) +
                         "; known IDs: " + KnownIds());
  }
  if (FindOperatorTraits(id)->geometric() && reference_frame == nullptr) {
    return InvalidArgumentError("operator " + std::string(name) + " needs a reference frame");
  }
  auto need_weights = [&](WeightLayout layout) -> Status {
    if (weights == nullptr || weights->layout != layout) {
      return InvalidArgumentError(
          "operator " + std::string(name) + " needs " +
          (layout == WeightLayout::kPerEdge ? "per-edge" : "per-directed-edge") + " weights");
    }
    return Status::Ok();
  };
  switch (id) {
    case OperatorId::kKirchhoff:
      return BuildKirchhoff(topology);
    case OperatorId::kTutte:
      return BuildTutte(topology);
    case OperatorId::kCotan:
      return BuildCotan(topology, *reference_frame);
    case OperatorId::kCotanArea:
      return BuildCotanArea(topology, *reference_frame);
    case OperatorId::kCotanSym:
      return BuildCotanSym(topology, *reference_frame);
    case OperatorId::kMeanValue:
      return BuildMeanValue(topology, *reference_frame);
    case OperatorId::kDdl:
      DMC_RETURN_IF_ERROR(need_weights(WeightLayout::kPerEdge));
      return OperatorFromWeights("ddl", topology, *weights, true);
    case OperatorId::kDdlAsym:
      DMC_RETURN_IF_ERROR(need_weights(WeightLayout::kPerDirectedEdge));
      return OperatorFromWeights("ddl-asym", topology, *weights, true);
    case OperatorId::kInvalid:
      break;
  }
  return NotFoundError("operator ID 0 is reserved as invalid; known IDs: " + KnownIds());
}

}  // namespace dmc

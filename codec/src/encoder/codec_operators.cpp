#include "encoder/codec_operators.h"

#include <string>

#include "dmc/operator_traits.h"

namespace dmc {

StatusOr<OperatorId> CodecOperatorId(std::string_view name) {
  const OperatorTraits* traits = FindOperatorTraits(name);
  if (traits != nullptr && traits->codec()) return traits->id;
  std::string names;
  for (const OperatorTraits& row : kOperatorTraits) {
    if (row.codec()) names += (names.empty() ? "" : ", ") + std::string(row.name);
  }
  if (traits != nullptr) {
    return UnsupportedError("operator '" + std::string(name) +
                            "' cannot be used by the codec (codec operators: " + names + ")");
  }
  return NotFoundError("unknown operator '" + std::string(name) + "' (codec operators: " + names +
                       ")");
}

std::string_view CodecOperatorName(OperatorId id) {
  const OperatorTraits* traits = FindOperatorTraits(id);
  return traits != nullptr && traits->codec() ? traits->name : "unknown";
}

}  // namespace dmc

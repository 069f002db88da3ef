#include "encoder/codec_operators.h"

#include <string>

#include "dmc/operators.h"

namespace dmc {
namespace {

struct CodecOperator {
  std::string_view name;
  OperatorId id;
};
constexpr CodecOperator kCodecOperators[] = {{"ddl", OperatorId::kDdl},
                                             {"tutte", OperatorId::kTutte},
                                             {"kirchhoff", OperatorId::kKirchhoff},
                                             {"cotan", OperatorId::kCotan},
                                             {"cotan-area", OperatorId::kCotanArea},
                                             {"cotan-sym", OperatorId::kCotanSym},
                                             {"mean-value", OperatorId::kMeanValue}};

}  // namespace

StatusOr<OperatorId> CodecOperatorId(std::string_view name) {
  for (const auto& op : kCodecOperators) {
    if (op.name == name) return op.id;
  }
  std::string names;
  for (const auto& op : kCodecOperators)
    names += (names.empty() ? "" : ", ") + std::string(op.name);
  if (FindOperator(name).ok()) {
    return UnsupportedError("operator '" + std::string(name) +
                            "' cannot be used by the codec (codec operators: " + names + ")");
  }
  return NotFoundError("unknown operator '" + std::string(name) + "' (codec operators: " + names +
                       ")");
}

std::string_view CodecOperatorName(OperatorId id) {
  for (const auto& op : kCodecOperators) {
    if (op.id == id) return op.name;
  }
  return "unknown";
}

}  // namespace dmc

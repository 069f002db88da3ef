#include "encoder/encoder_options.h"

#include <cmath>
#include <string>

#include "bitstream/format.h"
#include "encoder/codec_operators.h"

namespace dmc {

Status ValidateOptions(const EncoderOptions& o) {
  auto bad = [](const std::string& what) { return InvalidArgumentError(what); };
  if (o.rank < 0 || o.rank > static_cast<int>(format::kMaxRank)) {
    return bad("--rank must be in [0, " + std::to_string(format::kMaxRank) + "], got " +
               std::to_string(o.rank));
  }
  if (o.basis_bits < 2 || o.basis_bits > 16) {
    return bad("--basis-bits must be in [2, 16], got " + std::to_string(o.basis_bits));
  }
  if (o.residual_bits < 1 || o.residual_bits > 30) {
    return bad("--residual-bits must be in [1, 30], got " + std::to_string(o.residual_bits));
  }
  if (!std::isfinite(o.residual_step) || o.residual_step < 0.0) {
    return bad("--residual-step must be a finite value >= 0");
  }
  if (!std::isfinite(o.rank_threshold) || o.rank_threshold <= 0.0) {
    return bad("--rank-threshold must be positive");
  }
  if (o.anchors < -1) return bad("--anchors must be >= 1, or -1 for automatic");
  if (!std::isfinite(o.anchor_step_ratio) || o.anchor_step_ratio <= 0.0) {
    return bad("anchor step ratio must be positive");
  }
  if (o.segment_frames < 0 || o.segment_frames > static_cast<int>(format::kMaxSegmentFrames)) {
    return bad("--segment-frames must be in [0, " + std::to_string(format::kMaxSegmentFrames) +
               "]");
  }
  if (o.reference_bits < 4 || o.reference_bits > 30) {
    return bad("--reference-bits must be in [4, 30], got " + std::to_string(o.reference_bits));
  }
  if (o.weight_bits < 2 || o.weight_bits > 20) {
    return bad("--weight-bits must be in [2, 20], got " + std::to_string(o.weight_bits));
  }
  if (!(o.ddl_dead_zone == 0.0 || o.ddl_dead_zone >= 0.5)) {
    return bad("--ddl-dead-zone must be 0 (automatic) or >= 0.5");
  }
  if (!std::isfinite(o.ddl_regularization) || o.ddl_regularization < 0.0) {
    return bad("--ddl-mu must be >= 0");
  }
  if (!std::isfinite(o.target_bpfv) || o.target_bpfv < 0.0 || !std::isfinite(o.target_sted) ||
      o.target_sted < 0.0) {
    return bad("targets must be finite and >= 0");
  }
  if (o.target_bpfv > 0.0 && o.target_sted > 0.0) {
    return bad("give --target-bpfv or --target-sted, not both");
  }
  return CodecOperatorId(o.operator_name).status();
}

}  // namespace dmc

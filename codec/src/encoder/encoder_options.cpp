#include "dmc/encoder_options.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "bitstream/format.h"
#include "encoder/codec_operators.h"

namespace dmc {

Status ValidateOptions(const EncoderOptions& o, OptionSpelling spelling) {
  // Every name passes through the table's spelling, so the CLI shows its flags and the library
  // and Python the option names.
  auto bad = [&](std::string_view option, const std::string& what) {
    return InvalidArgumentError(SpellOption(option, spelling) + " " + what);
  };
  auto in_range = [](int low, int high, int value) {
    return "must be in [" + std::to_string(low) + ", " + std::to_string(high) + "], got " +
           std::to_string(value);
  };
  if (o.effort < 0 || o.effort > kMaxEffort) {
    return bad("effort", in_range(0, kMaxEffort, o.effort));
  }
  if (o.rank < 0 || o.rank > static_cast<int>(format::kMaxRank)) {
    return bad("rank", in_range(0, static_cast<int>(format::kMaxRank), o.rank));
  }
  if (o.basis_bits < 2 || o.basis_bits > 16) {
    return bad("basis_bits", in_range(2, 16, o.basis_bits));
  }
  if (o.residual_bits < 1 || o.residual_bits > 30) {
    return bad("residual_bits", in_range(1, 30, o.residual_bits));
  }
  if (!std::isfinite(o.residual_step) || o.residual_step < 0.0) {
    return bad("residual_step", "must be a finite value >= 0");
  }
  if (!std::isfinite(o.rank_threshold) || o.rank_threshold <= 0.0) {
    return bad("rank_threshold", "must be positive");
  }
  if (o.anchors < -1) return bad("anchors", "must be >= 1, or -1 for automatic");
  if (!std::isfinite(o.anchor_step_ratio) || o.anchor_step_ratio <= 0.0) {
    return bad("anchor_step_ratio", "must be positive");
  }
  if (!std::isfinite(o.residual_rdo_lambda) || o.residual_rdo_lambda < 0.0) {
    return bad("residual_rdo_lambda", "must be finite and >= 0");
  }
  if (!(o.step_shaping == -1.0 || (o.step_shaping >= 0.0 && o.step_shaping <= 2.0))) {
    return bad("step_shaping", "must be -1 (automatic) or within [0, 2]");
  }
  if (o.segment_frames < 0 || o.segment_frames > static_cast<int>(format::kMaxSegmentFrames)) {
    return bad("segment_frames",
               in_range(0, static_cast<int>(format::kMaxSegmentFrames), o.segment_frames));
  }
  if (o.reference_bits < 4 || o.reference_bits > 30) {
    return bad("reference_bits", in_range(4, 30, o.reference_bits));
  }
  if (o.weight_bits != 0 && (o.weight_bits < 2 || o.weight_bits > 20)) {
    return bad("weight_bits",
               "must be 0 (automatic) or in [2, 20], got " + std::to_string(o.weight_bits));
  }
  if (!(o.ddl_dead_zone == 0.0 || o.ddl_dead_zone >= 0.5)) {
    return bad("ddl_dead_zone", "must be 0 (automatic) or >= 0.5");
  }
  if (!std::isfinite(o.ddl_mu) || o.ddl_mu < 0.0) {
    return bad("ddl_mu", "must be >= 0");
  }
  if (!std::isfinite(o.target_bpfv) || o.target_bpfv < 0.0) {
    return bad("target_bpfv", "must be finite and >= 0");
  }
  if (!std::isfinite(o.fps) || o.fps < 0.0 || o.fps > 1e6) {
    return bad("fps",
               "must be a frame rate in frames per second, 0 < fps <= 10^6 (0 = the input's)");
  }
  if (!std::isfinite(o.target_sted) || o.target_sted < 0.0) {
    return bad("target_sted", "must be finite and >= 0");
  }
  if (o.target_bpfv > 0.0 && o.target_sted > 0.0) {
    return InvalidArgumentError("give " + SpellOption("target_bpfv", spelling) + " or " +
                                SpellOption("target_sted", spelling) + ", not both");
  }
  return CodecOperatorId(o.operator_name).status();
}

Status CheckGivenSwitches(const EncoderOptions& o, std::span<const std::string> given,
                          OptionSpelling spelling) {
  auto named = [&](std::string_view name) {
    return std::find(given.begin(), given.end(), name) != given.end();
  };
  auto refuse = [&](std::string_view option, int from) {
    return InvalidArgumentError(SpellOption(option, spelling) + " asks for a search that " +
                                SpellOption("effort", spelling) + " " + std::to_string(o.effort) +
                                " does not do (it does from " + std::to_string(from) + " up)");
  };
  if (o.ddl_fallback && named("ddl_fallback") && o.effort < kFallbackEffort) {
    return refuse("ddl_fallback", kFallbackEffort);
  }
  if (o.rank_search && named("rank_search") && o.effort < kRankSearchEffort) {
    return refuse("rank_search", kRankSearchEffort);
  }
  return Status::Ok();
}

}  // namespace dmc

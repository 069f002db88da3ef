// The encoder option table (dmc/encoder_options.h): one row per EncoderOptions field.
#include <algorithm>
#include <string>

#include "dmc/encoder_options.h"

namespace dmc {
namespace {

using O = EncoderOptions;

constexpr EncoderOptionSpec kOptions[] = {
    {"operator", &O::operator_name,
     "Laplace operator: ddl, tutte, kirchhoff, cotan, cotan-area, cotan-sym, mean-value"},
    {"effort", &O::effort,
     "Search effort 0..9: 0 = one pass (threshold rank, fitted ddl weights), 1 = also the ddl "
     "fallback, 2 (default) to 9 = also the rank search, each level measuring more candidates on "
     "more frames; 8 = the exhaustive search of earlier versions, 9 = it on every frame. A fixed "
     "rank, --no-rank-search and --no-ddl-fallback restrict every level; --rank-search or "
     "--ddl-fallback given with a level that does not do that search is an error"},
    {"rank", &O::rank, "PCA basis vectors per segment; 0 = automatic"},
    {"rank_threshold", &O::rank_threshold,
     "Automatic rank: keep components with eigenvalue > T * V * step^2"},
    {"basis_bits", &O::basis_bits, "Basis quantisation bits (2..16)"},
    {"residual_bits", &O::residual_bits, "Residual step = bounding-box diagonal * 2^-bits"},
    {"residual_step", &O::residual_step, "Absolute residual step; > 0 overrides the bits"},
    {"anchors", &O::anchors,
     "Anchor vertices per segment; -1 = automatic: 1 % of the vertices, 2 % in segments of 128 "
     "frames or more, at most 1000"},
    {"anchor_step_ratio", &O::anchor_step_ratio,
     "Anchor quantisation step relative to the residual step"},
    {"residual_rdo_lambda", &O::residual_rdo_lambda,
     "Rate-distortion optimised residual rounding: round a value one level toward zero when "
     "that lowers (error in steps)^2 + lambda * bits; 0 = plain rounding"},
    {"step_shaping", &O::step_shaping,
     "STED-aware step shaping strength: each anchor region's residual step scaled by (mean edge "
     "length / geometric mean)^strength; -1 = automatic from the mesh's edge-length spread, 0 = "
     "off, up to 2"},
    {"segment_frames", &O::segment_frames, "Maximum frames per segment; 0 = default"},
    {"reference_bits", &O::reference_bits,
     "Geometric operators: reference frame step = diagonal * 2^-bits"},
    {"weight_bits", &O::weight_bits,
     "DDL weight step 2^-bits (2..20); 0 = automatic: 8 for segments of 128 frames or more, else "
     "7"},
    {"ddl_mu", &O::ddl_mu, "DDL Tikhonov pull toward Tutte (relative)"},
    {"ddl_dead_zone", &O::ddl_dead_zone,
     "DDL weights this close to their prediction (weight units) are sent as predicted: 0.5 = "
     "rounding, inf = predicted only, 0 = choose per segment"},
    {"ddl_fallback", &O::ddl_fallback,
     "ddl: code a segment with kirchhoff, tutte or mean-value instead when that has the lower "
     "rate at equal STED (effort >= 1); false = always the fitted weights"},
    {"rank_search", &O::rank_search,
     "ddl with its fallback and an automatic rank: also code each segment at the ranks of 1/4, 2 "
     "and 4 times the rank threshold and keep the lowest bits * STED^1.3 (effort >= 2); false = "
     "the threshold's rank alone"},
    {"uniform_weight_prediction", &O::uniform_weight_prediction,
     "Predict DDL weights by the thesis's uniform share, not the degree reference"},
    {"target_bpfv", &O::target_bpfv,
     "> 0: search the residual step for this rate (bits per frame and vertex)"},
    {"target_sted", &O::target_sted, "> 0: search the residual step for this STED"},
    {"allow_reorder", &O::allow_reorder,
     "Let the stream use the codec's own vertex order (smaller connectivity)"},
    {"fps", &O::fps,
     "Frames per second recorded in the stream, for inputs without a rate (OBJ/OFF/PLY frames, "
     "PC2); 0 = the input's own rate"},
    {"measure", &O::measure, "Decode the stream and measure KG/STED", /*shapes_stream=*/false},
};

}  // namespace

std::span<const EncoderOptionSpec> EncoderOptionTable() { return kOptions; }

const EncoderOptionSpec* FindEncoderOption(std::string_view name) {
  const auto* found =
      std::find_if(std::begin(kOptions), std::end(kOptions),
                   [&](const EncoderOptionSpec& spec) { return spec.name == name; });
  return found == std::end(kOptions) ? nullptr : found;
}

std::string SpellOption(std::string_view name, OptionSpelling spelling) {
  if (spelling == OptionSpelling::kName) return std::string(name);
  std::string flag = "--" + std::string(name);
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

}  // namespace dmc

// Encoding mesh sequences to .dmc streams (trajectory PCA -> Laplace operator -> high-pass
// quantisation -> adaptive range coding), with closed-loop distortion measurement.
//
// Contract: Encode validates its input (ValidateSequence) and options; the encoder works in
// closed loop (every quantity it derives uses what the decoder will rebuild), and when
// EncoderOptions::measure is set it decodes its own stream with the real decoder, so the reported
// KG/STED are exactly those of `dmc decode`'s output. Output bytes are identical for identical
// input and options, whatever the thread count.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "dmc/metrics.h"
#include "dmc/sequence.h"
#include "dmc/status.h"

namespace dmc {

struct EncoderOptions {
  std::string operator_name = "ddl";  // any codec-capable operator of the registry
  int rank = 0;                       // PCA basis vectors per segment; 0 = automatic
  // Automatic rank keeps component k while its eigenvalue λ_k > rank_threshold · V · Δ² (Δ the
  // residual step): a component is worth its coefficients while dropping it would cost more
  // squared error than quantising it does.
  double rank_threshold = 10.0;
  int basis_bits = 10;             // basis quantisation bits (2..16)
  int residual_bits = 10;          // residual step = bbox diagonal * 2^-residual_bits
  double residual_step = 0.0;      // absolute step; overrides residual_bits when > 0
  int anchors = -1;                // anchor vertices per segment; -1 = automatic
  double anchor_step_ratio = 1.0;  // anchor quantisation step / residual step
  int segment_frames = 0;          // maximum frames per segment; 0 = default
  int reference_bits = 10;  // geometric operators: reference frame step = diagonal · 2^-bits
  int weight_bits = 7;      // DDL weight step 2^-weight_bits
  double ddl_regularization = 0.1;  // DDL Tikhonov pull toward Tutte (relative)
  // DDL weights within this many units of their prediction are sent as the prediction (0.5 =
  // plain rounding; infinity = predicted weights only). 0 = per segment, whichever of the two
  // gives the smaller payload at the same step: better rate–STED on short segments (crane), but
  // it can raise the largest vertex error several-fold, so it is not the default.
  double ddl_dead_zone = 0.5;
  // DDL weight prediction: false = shared in proportion to a degree-based reference weight,
  // true = shared equally (the thesis's p = (1 - Σ known)/|unknown|).
  bool weight_prediction_uniform = false;
  double target_bpfv = 0.0;    // > 0: search parameters for this rate
  double target_sted = 0.0;    // > 0: search parameters for this distortion
  bool allow_reorder = false;  // let the output use the codec's own vertex order
  bool measure = true;         // decode and measure KG/STED
};

struct EncodeReport {
  uint64_t bytes = 0;
  double bpfv = 0.0;
  int frames = 0;
  int vertices = 0;
  DistortionReport distortion;  // valid when measured
  bool measured = false;
  double seconds = 0.0;
  // Bytes per syntax element, over all segments (chunk framing included).
  uint64_t header_bytes = 0, connectivity_bytes = 0, mean_bytes = 0, basis_bytes = 0,
           operator_bytes = 0, anchor_bytes = 0, residual_bytes = 0;
  // What rate control chose (of the first segment when they differ).
  int rank = 0;
  int anchors = 0;
  int residual_bits_equivalent = 0;
  double residual_step = 0.0;
  int segments = 0;
};

StatusOr<std::vector<uint8_t>> Encode(const MeshSequence& sequence, const EncoderOptions& options,
                                      EncodeReport* report = nullptr);

// Encodes and writes atomically (temporary file, then rename).
Status EncodeToFile(const MeshSequence& sequence, const std::filesystem::path& output,
                    const EncoderOptions& options, EncodeReport* report = nullptr);

}  // namespace dmc

// Rate–distortion sweeps: dmc at a ladder of rates for each Laplace operator, and the baseline
// codecs (sweep/baselines.h) at a ladder of quantisations, every point encoded, decoded by the
// real decoder and measured against the input with one DistortionMeter (so all curves share
// exactly the same KG and STED).
//
// The dmc ladder varies the residual step: rung k of N uses
//   residual_bits = min + k·(max − min)/(N − 1),  residual step = bbox diagonal · 2^−residual_bits
// (fractional bits allowed), the rank following automatically through the encoder's rank
// threshold and the basis precision through BasisBitsFor. On the real 10k-vertex captures the
// default 5–16 bits spans about 0.4–8 bpfv with Tutte on samba (30 frames) and 0.7–9 on crane
// (16 frames); the low end is bounded by the connectivity, sent once (0.31 bpfv on samba), and by
// each operator's side information. Baselines use the integer quantisation bits spread evenly over
// [min_baseline_bits, max_baseline_bits] (duplicates removed).
//
// Timing: encode_s is the wall-clock time of Encode without its own measurement, decode_s that of
// the decoder alone (for baselines: decompression, dequantisation and the vertex renumbering).
// Points run one after another, so each may use every core (TBB inside the codec).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "dmc/encoder.h"
#include "dmc/metrics.h"
#include "dmc/sequence.h"
#include "dmc/status.h"
#include "sweep/baselines.h"

namespace dmc::sweep {

// One encoded and measured point.
struct RdPoint {
  std::string codec;          // "dmc" or a baseline name
  std::string operator_name;  // dmc: the Laplace operator; empty for baselines
  int rank = -1;              // dmc: PCA rank of the first segment; -1 for baselines
  int basis_bits = -1;        // dmc: basis quantisation bits; -1 for baselines
  double residual_bits = 0;   // dmc: log2(diagonal / residual step); baselines: position bits
  int anchors = -1;           // dmc: anchors of the first segment; -1 for baselines
  int segments = -1;          // dmc: segments of the stream; -1 for baselines
  // dmc: the operator each segment was coded with, as "name:count" in order of first use,
  // space-separated ("ddl:2 tutte:1"); empty for baselines.
  std::string segment_operators;
  uint64_t bytes = 0;
  // dmc: bytes per syntax element (EncodeReport's, they sum to `bytes`); 0 for baselines.
  uint64_t header_bytes = 0, connectivity_bytes = 0, mean_bytes = 0, basis_bytes = 0,
           operator_bytes = 0, anchor_bytes = 0, residual_bytes = 0;
  double bpfv = 0.0;
  double kg = 0.0;
  double sted = 0.0;
  double encode_s = 0.0;
  double decode_s = 0.0;

  // The curve the point belongs to: "dmc/<operator>" or the baseline name.
  std::string Curve() const;
};

struct SweepOptions {
  // Codec operators to sweep, in this order. Operators the registry knows but the codec cannot
  // use yet are skipped with a warning; unknown names are an error.
  std::vector<std::string> operators = {"ddl", "tutte", "kirchhoff", "mean-value", "cotan"};
  std::vector<BaselineKind> baselines = AllBaselines();
  int points = 8;  // rungs per curve, ≥ 2
  double min_residual_bits = 5.0;
  double max_residual_bits = 16.0;
  // The dmc rungs given one by one (residual bits); when not empty they replace the even ladder
  // of points / min / max (which still spaces the baselines' bits).
  std::vector<double> ladder;
  int basis_bits = 0;                    // 0: follow the rung (BasisBitsFor), else fixed (2..16)
  int effort = EncoderOptions().effort;  // the dmc encoder's search effort, 0..kMaxEffort
  // Every other dmc encoder option of every point (the rank threshold, anchors, residual
  // rounding, …): the ladder sets operator_name, residual_step, basis_bits and effort from the
  // fields above, and measure is off (the sweep measures). SetEncoderOption fills it by name.
  EncoderOptions encoder;
  int min_baseline_bits = 8;
  int max_baseline_bits = 16;
  StedOptions sted;
};

// kInvalidArgument naming the first bad field: points < 2, residual bits (of the range or of an
// explicit ladder rung) outside [1, 30] or min > max, basis_bits not 0 or in [2, 16], effort
// outside [0, kMaxEffort], baseline bits outside [kMinBaselineBits, kMaxBaselineBits] or min > max,
// no operator and no baseline, invalid STED options.
Status ValidateSweepOptions(const SweepOptions& options);

// Sets one option of `options` from "NAME=VALUE", NAME an encoder option table name
// (dmc/encoder_options.h) and VALUE its type's text (a switch: true/false/on/off/1/0).
// kInvalidArgument naming the setting when it has no '=', VALUE does not parse entirely, or NAME
// is unknown or one the ladder sets (operator, residual_bits, residual_step, basis_bits, effort,
// measure, target_bpfv, target_sted).
Status SetEncoderOption(EncoderOptions* options, std::string_view setting);

// The rungs of the dmc ladder (fractional bits, increasing, distinct): the explicit ladder when
// given, else `points` rungs evenly over [min_residual_bits, max_residual_bits].
std::vector<double> ResidualBitsLadder(const SweepOptions& options);
// The baseline quantisation bits (integers, increasing, distinct).
std::vector<int> BaselineBitsLadder(const SweepOptions& options);
// Basis bits for a rung when not fixed: clamp(round(residual_bits), 10, 16). Measured on samba:
// below ~9 residual bits 10 basis bits cost nothing in STED; above, a coarser basis floors KG
// (at 14 residual bits, 10 basis bits give KG 0.26 and 14 give 0.06 for 0.3 % more rate).
int BasisBitsFor(double residual_bits, int fixed_basis_bits);

struct SweepResult {
  std::vector<RdPoint> points;        // in sweep order: operators' ladders, then baselines
  std::vector<std::string> warnings;  // skipped operators, baselines or points, one sentence each
  // What `dmc encode` gives with its default rate settings (the default operator, residual and
  // basis bits and effort; the sweep's other encoder options): swept when the default operator
  // is, kept apart from the curves (it is in no curve, table statistic or yardstick row).
  std::optional<RdPoint> default_point;
};

// Called after each point with the number of points done and the (current) total; the total
// shrinks when a curve is skipped. `warning` is non-empty when the step produced one.
using SweepCallback =
    std::function<void(const RdPoint* point, const std::string& warning, int done, int total)>;

// Runs the sweep on `sequence` (validated here). Fails on invalid options or input, on an unknown
// operator (kNotFound) and when the metrics cannot be computed (kInvalidSequence: a degenerate
// original). A point that fails to encode or decode is skipped with a warning, and a whole curve
// is skipped when its codec cannot handle the input (kUnsupported).
StatusOr<SweepResult> RunSweep(const MeshSequence& sequence, const SweepOptions& options,
                               const SweepCallback& callback = {});

}  // namespace dmc::sweep

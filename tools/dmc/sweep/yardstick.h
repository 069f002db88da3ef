// The rate–distortion yardstick: dmc's ladders on named sequences as rows of a CSV (the committed
// baseline, bench/rd/baseline.csv, and what `dmc sweep` writes as yardstick.csv), and a new sweep
// compared with the baseline's curve for the same sequence (`dmc sweep --baseline FILE`).
//
// The CSV: lines starting with '#' are comments, "# key: value" ones the metadata (commit, tree,
// dmc version, command); then the header kYardstickHeader and one row per dmc point. Columns are
// found by name, so a file with more columns (or in another order) still reads.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dmc/status.h"
#include "sweep/rd_analysis.h"
#include "sweep/sweep.h"

namespace dmc::sweep {

struct YardstickRow {
  std::string sequence;
  int vertices = 0;
  int frames = 0;
  std::string operator_name;  // the operator asked for (the stream may use its fallbacks)
  int effort = 0;
  double residual_bits = 0.0;  // the ladder parameter: residual step = diagonal · 2^-bits
  int basis_bits = 0;
  int rank = 0;  // of the first segment
  int segments = 0;
  std::string segment_operators;  // as RdPoint::segment_operators
  uint64_t bytes = 0;
  double bpfv = 0.0;
  double kg = 0.0;
  double sted = 0.0;
  uint64_t header_bytes = 0, connectivity_bytes = 0, mean_bytes = 0, basis_bytes = 0,
           operator_bytes = 0, anchor_bytes = 0, residual_bytes = 0;
};

using YardstickMeta = std::vector<std::pair<std::string, std::string>>;

struct Yardstick {
  YardstickMeta meta;  // "# key: value" lines, in file order
  std::vector<YardstickRow> rows;
};

// The header line, exactly, as YardstickCsv writes it.
inline constexpr const char* kYardstickHeader =
    "sequence,vertices,frames,operator,effort,residual_bits,bpfv,kg,sted,bytes,rank,basis_bits,"
    "segments,segment_operators,header_bytes,connectivity_bytes,mean_bytes,basis_bytes,"
    "operator_bytes,anchor_bytes,residual_bytes";

// The rows of the dmc points of a sweep of `sequence` (baseline codecs' points are left out).
std::vector<YardstickRow> YardstickRows(const std::string& sequence, int vertices, int frames,
                                        int effort, const std::vector<RdPoint>& points);

// The metadata as comment lines, the header, the rows. Numbers are written exactly (the shortest
// text that reads back as the same double).
std::string YardstickCsv(const YardstickMeta& meta, const std::vector<YardstickRow>& rows);

// Reads a YardstickCsv text. kParseError naming the line (1-based) and the column for a missing
// header, a missing required column (sequence, vertices, frames, residual_bits, bpfv, kg, sted),
// a row with the wrong number of fields or a field that is not a number where one is needed.
// Optional columns that are absent read as 0 or empty.
StatusOr<Yardstick> ParseYardstick(std::string_view text);

// The baseline's curve for `sequence`, its rows in file order. kNotFound (naming the sequences the
// baseline has) when there is none; kMismatch when the baseline's vertex or frame count differs
// from the input's (another excerpt of the capture is another sequence); kInvalidArgument when
// the rows mix operators (one curve per sequence).
StatusOr<std::vector<YardstickRow>> BaselineCurve(const Yardstick& baseline,
                                                  const std::string& sequence, int vertices,
                                                  int frames);

// The name a sequence is known by in the yardstick: a directory's own name, a glob's directory's
// name, a file's name without its extension (".../crane-full/crane-full.pc2" -> "crane-full").
std::string SequenceNameOf(const std::string& input);

// (bpfv, STED) and (bpfv, KG) samples of rows.
std::vector<RdSample> StedSamples(const std::vector<YardstickRow>& rows);
std::vector<RdSample> KgSamples(const std::vector<YardstickRow>& rows);

// The row whose STED is nearest `sted` in the log (ties: the cheaper); rows must not be empty.
const YardstickRow& NearestToSted(const std::vector<YardstickRow>& rows, double sted);

// One current curve against the baseline's.
struct BaselineComparison {
  std::string curve;                   // "dmc/<operator>"
  std::optional<double> bd_rate_sted;  // percent, negative = fewer bits (BjontegaardDeltaRate)
  std::optional<double> bd_rate_kg;
  struct Target {
    double sted = 0.0;
    RateAtTarget baseline, current;
  };
  std::vector<Target> targets;
  YardstickRow baseline_near, current_near;  // the points nearest breakdown_sted
};

// `current` holds one curve's rows (one operator), `baseline` the rows of BaselineCurve; neither
// empty.
BaselineComparison CompareWithBaseline(const std::vector<YardstickRow>& baseline,
                                       const std::vector<YardstickRow>& current,
                                       const std::vector<double>& sted_targets,
                                       double breakdown_sted);

// Markdown: per curve the BD-rates, the bpfv at each target (current and baseline) and the
// per-element shares of the points nearest the breakdown STED.
std::string ComparisonMarkdown(const std::string& sequence,
                               const std::vector<BaselineComparison>& comparisons,
                               double breakdown_sted);

}  // namespace dmc::sweep

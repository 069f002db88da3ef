// What `dmc sweep` writes: rd.csv, the two plots and summary.md.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "dmc/metrics.h"
#include "sweep/rd_analysis.h"
#include "sweep/svg_plot.h"
#include "sweep/sweep.h"

namespace dmc::sweep {

// The CSV header, exactly.
inline constexpr const char* kRdCsvHeader =
    "codec,operator,rank,basis_bits,residual_bits,anchors,bpfv,kg,sted,encode_s,decode_s,"
    "coded_as,default_settings";

// rd.csv: the header, then one row per point in sweep order. Fields that do not apply (operator,
// rank, basis_bits and anchors of a baseline) are empty; a baseline's residual_bits column holds
// its position quantisation bits. Numbers use up to 6 significant digits (seconds 4 decimals).
std::string RdCsv(const std::vector<RdPoint>& points,
                  const std::optional<RdPoint>& default_point = std::nullopt);

// The curves in the order they were swept ("dmc/<op>" first, then the baselines).
std::vector<std::string> CurveNames(const std::vector<RdPoint>& points);

// Table cells of the summaries (summary.md, baseline.md): a rate for a target as interpolated,
// "≤ r" below or "> r" above the curve's range, "–" when there is none; a signed percentage.
std::string RateCell(const RateAtTarget& rate);
std::string PercentCell(const std::optional<double>& percent);

enum class RdMetric { kSted, kKg };

// The rate–distortion plot of one metric: bpfv on a log x axis, the metric on a log y axis, one
// series per curve (baselines dashed), and the default settings' point marked when given.
PlotSpec RdPlot(const std::vector<RdPoint>& points, RdMetric metric, const std::string& subtitle,
                const std::optional<RdPoint>& default_point = std::nullopt);

struct SummaryContext {
  std::string input;    // what was swept, as given
  std::string command;  // the command line, for reproduction
  int vertices = 0;
  int frames = 0;
  StedOptions sted;
  std::vector<double> sted_targets = {0.01, 0.02, 0.05};
  // BD-rates are against each of these curves that the sweep has: the default operator's curve
  // (or, without it, the first dmc curve) and per-frame Draco.
  std::vector<std::string> bd_anchors = {"dmc/ddl", "draco"};
  std::optional<RdPoint> default_point;  // SweepResult::default_point
  std::vector<std::string> warnings;
};

// The "rate needed for a target STED" table of summary.md (Markdown, with its explanation).
std::string RateTargetTable(const std::vector<RdPoint>& points, const SummaryContext& context);

// summary.md: per curve the bpfv needed for each STED target (interpolated on the curve's
// efficient points, log–log), the BD-rates in STED and in KG against the anchor curve, the speed,
// then every point as a table. Cells that cannot be interpolated say why: "≤ r" when the cheapest
// point already meets the target, "> r" when no point does.
std::string SummaryMarkdown(const std::vector<RdPoint>& points, const SummaryContext& context);

}  // namespace dmc::sweep

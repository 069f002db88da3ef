#include "sweep/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>

#include "dmc/encoder.h"
#include "sweep/rd_analysis.h"

namespace dmc::sweep {
namespace {

std::string OptionalInt(int value) { return value < 0 ? "" : std::to_string(value); }

std::string Number(double value) { return fmt::format("{:.6g}", value); }

std::vector<RdSample> Samples(const std::vector<RdPoint>& points, const std::string& curve,
                              RdMetric metric) {
  std::vector<RdSample> samples;
  for (const RdPoint& point : points) {
    if (point.Curve() == curve) {
      samples.push_back({point.bpfv, metric == RdMetric::kSted ? point.sted : point.kg});
    }
  }
  return samples;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t mid = values.size() / 2;
  return values.size() % 2 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
}

}  // namespace

std::string RateCell(const RateAtTarget& rate) {
  switch (rate.kind) {
    case RateAtTarget::Kind::kInterpolated:
      return fmt::format("{:.3g}", rate.rate);
    case RateAtTarget::Kind::kBelowRange:
      return fmt::format("≤ {:.3g}", rate.rate);
    case RateAtTarget::Kind::kAboveRange:
      return rate.rate > 0.0 ? fmt::format("> {:.3g}", rate.rate) : "–";
  }
  return "–";
}

std::string PercentCell(const std::optional<double>& percent) {
  return percent ? fmt::format("{:+.1f} %", *percent) : "–";
}

std::string RdCsv(const std::vector<RdPoint>& points, const std::optional<RdPoint>& default_point) {
  std::string csv = std::string(kRdCsvHeader) + "\n";
  const auto row = [&](const RdPoint& p, bool default_settings) {
    csv += fmt::format("{},{},{},{},{},{},{},{},{},{:.4f},{:.4f},{},{}\n", p.codec, p.operator_name,
                       OptionalInt(p.rank), OptionalInt(p.basis_bits), Number(p.residual_bits),
                       OptionalInt(p.anchors), Number(p.bpfv), Number(p.kg), Number(p.sted),
                       p.encode_s, p.decode_s, p.segment_operators, default_settings ? 1 : 0);
  };
  for (const RdPoint& p : points) row(p, false);
  if (default_point) row(*default_point, true);
  return csv;
}

std::vector<std::string> CurveNames(const std::vector<RdPoint>& points) {
  std::vector<std::string> names;
  for (const RdPoint& point : points) {
    const std::string curve = point.Curve();
    if (std::find(names.begin(), names.end(), curve) == names.end()) names.push_back(curve);
  }
  return names;
}

PlotSpec RdPlot(const std::vector<RdPoint>& points, RdMetric metric, const std::string& subtitle,
                const std::optional<RdPoint>& default_point) {
  PlotSpec spec;
  const bool sted = metric == RdMetric::kSted;
  spec.title = sted ? "Rate–distortion: STED" : "Rate–distortion: KG error";
  spec.subtitle = subtitle;
  spec.x_label = "rate (bits per frame and vertex, bpfv, log scale)";
  spec.y_label =
      sted ? "STED (log scale, lower is better)" : "KG error, % (log scale, lower is better)";
  for (const std::string& curve : CurveNames(points)) {
    PlotSeries series;
    series.label = curve;
    series.dashed = curve.rfind("dmc/", 0) != 0;
    for (const RdPoint& point : points) {
      if (point.Curve() == curve)
        series.points.emplace_back(point.bpfv, sted ? point.sted : point.kg);
    }
    spec.series.push_back(std::move(series));
  }
  if (default_point) {
    spec.marks.push_back({"dmc encode defaults (" + default_point->operator_name + ", " +
                              fmt::format("{:g}", default_point->residual_bits) + " bits)",
                          default_point->bpfv, sted ? default_point->sted : default_point->kg});
  }
  return spec;
}

std::vector<std::string> BdAnchors(const std::vector<RdPoint>& points,
                                   const SummaryContext& context) {
  const std::vector<std::string> curves = CurveNames(points);
  std::vector<std::string> anchors;
  for (const std::string& wanted : context.bd_anchors) {
    std::string anchor = wanted;
    if (std::find(curves.begin(), curves.end(), anchor) == curves.end()) {
      if (anchor.rfind("dmc/", 0) != 0) continue;
      // No default operator in this sweep: its first dmc curve instead.
      const auto dmc = std::find_if(curves.begin(), curves.end(),
                                    [](const std::string& c) { return c.rfind("dmc/", 0) == 0; });
      if (dmc == curves.end()) continue;
      anchor = *dmc;
    }
    if (std::find(anchors.begin(), anchors.end(), anchor) == anchors.end()) {
      anchors.push_back(anchor);
    }
  }
  return anchors;
}

std::string RateTargetTable(const std::vector<RdPoint>& points, const SummaryContext& context) {
  const std::vector<std::string> curves = CurveNames(points);
  const std::vector<std::string> anchors = BdAnchors(points, context);
  std::string md;
  md += "## Rate needed for a target STED (bpfv)\n\n";
  md += "| curve |";
  for (const double target : context.sted_targets) md += fmt::format(" STED {:g} |", target);
  for (const std::string& anchor : anchors) {
    md += fmt::format(" BD-rate vs {0} (STED) | BD-rate vs {0} (KG) |", anchor);
  }
  md += "\n|---|";
  for (size_t i = 0; i < context.sted_targets.size() + 2 * anchors.size(); ++i) md += "---:|";
  md += "\n";
  for (const std::string& curve : curves) {
    const std::vector<RdSample> sted_front = ParetoFront(Samples(points, curve, RdMetric::kSted));
    const std::vector<RdSample> kg_front = ParetoFront(Samples(points, curve, RdMetric::kKg));
    md += fmt::format("| {} |", curve);
    for (const double target : context.sted_targets) {
      md += fmt::format(" {} |", RateCell(RateForDistortion(sted_front, target)));
    }
    for (const std::string& anchor : anchors) {
      if (curve == anchor) {
        md += " 0 (anchor) | 0 (anchor) |";
        continue;
      }
      md += fmt::format(" {} | {} |",
                        PercentCell(BjontegaardDeltaRate(
                            ParetoFront(Samples(points, anchor, RdMetric::kSted)), sted_front)),
                        PercentCell(BjontegaardDeltaRate(
                            ParetoFront(Samples(points, anchor, RdMetric::kKg)), kg_front)));
    }
    md += "\n";
  }
  if (context.default_point) {
    const RdPoint& p = *context.default_point;
    md += fmt::format(
        "\n**Default settings** (`dmc encode` with no rate option: operator {}, {} residual "
        "bits, effort {}; the diamond on the plots): {:.4g} bpfv, KG {:.4g}, STED {:.4g}, rank "
        "{}, coded as {}.\n",
        p.operator_name, fmt::format("{:g}", p.residual_bits), EncoderOptions().effort, p.bpfv,
        p.kg, p.sted, p.rank, p.segment_operators);
  }
  md +=
      "\nRates are interpolated linearly in log–log between the two efficient points around the "
      "target (points that cost more for no gain are ignored). \"≤ r\": the cheapest point, at "
      "r bpfv, already meets the target; \"> r\": no point up to r bpfv reaches it. BD-rate: the "
      "average rate difference at equal distortion over the distortion range both curves cover "
      "(Bjøntegaard, monotone cubic interpolation of log rate over log distortion); negative "
      "means fewer bits than the anchor; \"–\" when the ranges do not overlap.\n\n";

  return md;
}

std::string SummaryMarkdown(const std::vector<RdPoint>& points, const SummaryContext& context) {
  const std::vector<std::string> curves = CurveNames(points);
  std::string md = fmt::format("# Rate–distortion sweep of `{}`\n\n", context.input);
  md += fmt::format(
      "{} vertices × {} frames. Every point was encoded, decoded and measured against the input "
      "with the same metrics (STED with w = {}, dt = {}, s = {}, c = {}). bpfv counts every byte "
      "a decoder reads.\n\n",
      context.vertices, context.frames, context.sted.width, context.sted.dt, context.sted.window,
      context.sted.c);
  if (!context.command.empty()) md += fmt::format("Command: `{}`\n\n", context.command);

  md += RateTargetTable(points, context);

  md += "## Speed (median over each curve's points)\n\n";
  md += "| curve | encode s | decode s | decoded vertex-frames / s | decode speed vs draco |\n";
  md += "|---|---:|---:|---:|---:|\n";
  std::map<std::string, double> median_decode;
  for (const std::string& curve : curves) {
    std::vector<double> decode;
    for (const RdPoint& point : points) {
      if (point.Curve() == curve) decode.push_back(point.decode_s);
    }
    median_decode[curve] = Median(decode);
  }
  for (const std::string& curve : curves) {
    std::vector<double> encode;
    for (const RdPoint& point : points) {
      if (point.Curve() == curve) encode.push_back(point.encode_s);
    }
    const double decode = median_decode[curve];
    const double vertex_frames = static_cast<double>(context.vertices) * context.frames;
    const auto draco = median_decode.find("draco");
    std::string ratio = "–";
    if (draco != median_decode.end() && decode > 0.0) {
      ratio = fmt::format("{:.2f}×", draco->second / decode);
    }
    md += fmt::format("| {} | {:.3f} | {:.3f} | {} | {} |\n", curve, Median(encode), decode,
                      decode > 0.0 ? fmt::format("{:.3g}", vertex_frames / decode) : "–", ratio);
  }
  md +=
      "\nWall-clock seconds on this machine, points run one at a time (each may use every "
      "core). Baseline decode times include decompression, dequantisation and the vertex "
      "renumbering back to input order.\n\n";

  if (!context.warnings.empty()) {
    md += "## Warnings\n\n";
    for (const std::string& warning : context.warnings) md += "- " + warning + "\n";
    md += "\n";
  }

  md += "## All points\n\n";
  md +=
      "| codec | operator | coded as | rank | basis bits | residual bits | anchors | bpfv | KG | "
      "STED | encode s | decode s |\n";
  md += "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const auto row = [&](const RdPoint& p, const std::string& note) {
    md += fmt::format(
        "| {} | {}{} | {} | {} | {} | {:.4g} | {} | {:.4g} | {:.4g} | {:.4g} | {:.3f} | "
        "{:.3f} |\n",
        p.codec, p.operator_name, note, p.segment_operators, OptionalInt(p.rank),
        OptionalInt(p.basis_bits), p.residual_bits, OptionalInt(p.anchors), p.bpfv, p.kg, p.sted,
        p.encode_s, p.decode_s);
  };
  for (const RdPoint& p : points) row(p, "");
  if (context.default_point) row(*context.default_point, " (default settings)");
  md +=
      "\nFor dmc, residual bits = log2(bounding-box diagonal / residual step), rank and "
      "anchors are those of the first segment, and \"coded as\" counts the operators the "
      "segments were coded with (the ddl operator's fallback may code one with kirchhoff, tutte "
      "or mean-value). For the baselines the residual-bits column holds "
      "the position quantisation bits (draco: per frame over the frame's box; meshopt and zstd: "
      "one cubic grid over the sequence's box).\n";
  return md;
}

}  // namespace dmc::sweep

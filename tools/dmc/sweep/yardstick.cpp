#include "sweep/yardstick.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>

#include "sweep/report.h"

namespace dmc::sweep {
namespace {

// The shortest text that reads back as the same double: a rerun compared with its own yardstick
// gives exactly 0.
std::string Number(double value) { return fmt::format("{}", value); }

std::vector<std::string_view> Split(std::string_view text, char separator) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t end = text.find(separator, start);
    fields.push_back(text.substr(start, end == std::string_view::npos ? end : end - start));
    if (end == std::string_view::npos) return fields;
    start = end + 1;
  }
}

std::string_view Trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) {
    text.remove_suffix(1);
  }
  return text;
}

template <typename T>
bool ParseNumber(std::string_view text, T& value) {
  if (text.empty()) return false;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

std::string Percent(uint64_t part, uint64_t whole) {
  return whole == 0 ? "–"
                    : fmt::format("{:.1f}",
                                  100.0 * static_cast<double>(part) / static_cast<double>(whole));
}

}  // namespace

std::vector<YardstickRow> YardstickRows(const std::string& sequence, int vertices, int frames,
                                        int effort, const std::vector<RdPoint>& points) {
  std::vector<YardstickRow> rows;
  for (const RdPoint& p : points) {
    if (p.codec != "dmc") continue;
    YardstickRow row;
    row.sequence = sequence;
    row.vertices = vertices;
    row.frames = frames;
    row.operator_name = p.operator_name;
    row.effort = effort;
    row.residual_bits = p.residual_bits;
    row.basis_bits = p.basis_bits;
    row.rank = p.rank;
    row.segments = p.segments;
    row.segment_operators = p.segment_operators;
    row.bytes = p.bytes;
    row.bpfv = p.bpfv;
    row.kg = p.kg;
    row.sted = p.sted;
    row.header_bytes = p.header_bytes;
    row.connectivity_bytes = p.connectivity_bytes;
    row.mean_bytes = p.mean_bytes;
    row.basis_bytes = p.basis_bytes;
    row.operator_bytes = p.operator_bytes;
    row.anchor_bytes = p.anchor_bytes;
    row.residual_bytes = p.residual_bytes;
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string YardstickCsv(const YardstickMeta& meta, const std::vector<YardstickRow>& rows) {
  std::string csv;
  for (const auto& [key, value] : meta) csv += fmt::format("# {}: {}\n", key, value);
  csv += std::string(kYardstickHeader) + "\n";
  for (const YardstickRow& r : rows) {
    csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
                       r.sequence, r.vertices, r.frames, r.operator_name, r.effort,
                       Number(r.residual_bits), Number(r.bpfv), Number(r.kg), Number(r.sted),
                       r.bytes, r.rank, r.basis_bits, r.segments, r.segment_operators,
                       r.header_bytes, r.connectivity_bytes, r.mean_bytes, r.basis_bytes,
                       r.operator_bytes, r.anchor_bytes, r.residual_bytes);
  }
  return csv;
}

StatusOr<Yardstick> ParseYardstick(std::string_view text) {
  Yardstick yardstick;
  std::map<std::string, size_t, std::less<>> column;
  size_t columns = 0;
  int line_number = 0;
  for (std::string_view line : Split(text, '\n')) {
    ++line_number;
    line = Trim(line);
    if (line.empty()) continue;
    if (line.front() == '#') {
      const std::string_view body = Trim(line.substr(1));
      const size_t colon = body.find(':');
      if (colon != std::string_view::npos) {
        yardstick.meta.emplace_back(std::string(Trim(body.substr(0, colon))),
                                    std::string(Trim(body.substr(colon + 1))));
      }
      continue;
    }
    const std::vector<std::string_view> fields = Split(line, ',');
    if (column.empty()) {
      for (size_t i = 0; i < fields.size(); ++i) column.emplace(std::string(Trim(fields[i])), i);
      columns = fields.size();
      for (const char* required :
           {"sequence", "vertices", "frames", "residual_bits", "bpfv", "kg", "sted"}) {
        if (!column.contains(required)) {
          return ParseError(fmt::format("yardstick line {}: the header has no '{}' column",
                                        line_number, required));
        }
      }
      continue;
    }
    if (fields.size() != columns) {
      return ParseError(fmt::format("yardstick line {}: {} fields, the header has {}", line_number,
                                    fields.size(), columns));
    }
    const auto field = [&](std::string_view name) -> std::string_view {
      const auto found = column.find(name);
      return found == column.end() ? std::string_view() : Trim(fields[found->second]);
    };
    YardstickRow row;
    Status bad = Status::Ok();
    const auto number = [&](std::string_view name, auto& value, bool required) {
      const std::string_view f = field(name);
      if (!bad.ok() || (!required && f.empty())) return;
      if (!ParseNumber(f, value)) {
        bad = ParseError(fmt::format("yardstick line {}: column '{}' holds '{}', not a number",
                                     line_number, name, f));
      }
    };
    row.sequence = std::string(field("sequence"));
    if (row.sequence.empty()) {
      return ParseError(fmt::format("yardstick line {}: empty sequence name", line_number));
    }
    row.operator_name = std::string(field("operator"));
    row.segment_operators = std::string(field("segment_operators"));
    number("vertices", row.vertices, true);
    number("frames", row.frames, true);
    number("residual_bits", row.residual_bits, true);
    number("bpfv", row.bpfv, true);
    number("kg", row.kg, true);
    number("sted", row.sted, true);
    number("effort", row.effort, false);
    number("basis_bits", row.basis_bits, false);
    number("rank", row.rank, false);
    number("segments", row.segments, false);
    number("bytes", row.bytes, false);
    number("header_bytes", row.header_bytes, false);
    number("connectivity_bytes", row.connectivity_bytes, false);
    number("mean_bytes", row.mean_bytes, false);
    number("basis_bytes", row.basis_bytes, false);
    number("operator_bytes", row.operator_bytes, false);
    number("anchor_bytes", row.anchor_bytes, false);
    number("residual_bytes", row.residual_bytes, false);
    if (!bad.ok()) return bad;
    yardstick.rows.push_back(std::move(row));
  }
  if (column.empty()) return ParseError("yardstick: no header line");
  return yardstick;
}

StatusOr<std::vector<YardstickRow>> BaselineCurve(const Yardstick& baseline,
                                                  const std::string& sequence, int vertices,
                                                  int frames) {
  std::vector<YardstickRow> rows;
  std::vector<std::string> known;
  for (const YardstickRow& row : baseline.rows) {
    if (row.sequence == sequence) rows.push_back(row);
    if (std::find(known.begin(), known.end(), row.sequence) == known.end()) {
      known.push_back(row.sequence);
    }
  }
  if (rows.empty()) {
    std::string names;
    for (const std::string& name : known) names += (names.empty() ? "" : ", ") + name;
    return NotFoundError(fmt::format("the baseline has no sequence '{}' (it has: {})", sequence,
                                     names.empty() ? "none" : names));
  }
  for (const YardstickRow& row : rows) {
    if (row.vertices != vertices || row.frames != frames) {
      return MismatchError(fmt::format(
          "the baseline's '{}' has {} vertices x {} frames, the input {} x {} (another excerpt "
          "needs its own name: --sequence)",
          sequence, row.vertices, row.frames, vertices, frames));
    }
    if (row.operator_name != rows.front().operator_name) {
      return InvalidArgumentError(
          fmt::format("the baseline's '{}' mixes operators '{}' and '{}': one curve per sequence",
                      sequence, rows.front().operator_name, row.operator_name));
    }
  }
  return rows;
}

std::string SequenceNameOf(const std::string& input) {
  std::filesystem::path path(input);
  while (!path.empty() && !path.has_filename() && path.has_parent_path() &&
         path.parent_path() != path) {
    path = path.parent_path();  // "crane/" -> "crane"
  }
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return path.filename().string();
  const std::string name = path.filename().string();
  if (name.find_first_of("*?[") != std::string::npos) {
    return path.parent_path().filename().string();
  }
  return path.stem().string();
}

std::vector<RdSample> StedSamples(const std::vector<YardstickRow>& rows) {
  std::vector<RdSample> samples;
  for (const YardstickRow& row : rows) samples.push_back({row.bpfv, row.sted});
  return samples;
}

std::vector<RdSample> KgSamples(const std::vector<YardstickRow>& rows) {
  std::vector<RdSample> samples;
  for (const YardstickRow& row : rows) samples.push_back({row.bpfv, row.kg});
  return samples;
}

const YardstickRow& NearestToSted(const std::vector<YardstickRow>& rows, double sted) {
  const auto distance = [&](const YardstickRow& row) {
    return row.sted > 0.0 ? std::abs(std::log(row.sted / sted)) : HUGE_VAL;
  };
  const YardstickRow* best = &rows.front();
  for (const YardstickRow& row : rows) {
    const double d = distance(row), b = distance(*best);
    if (d < b || (d == b && row.bpfv < best->bpfv)) best = &row;
  }
  return *best;
}

BaselineComparison CompareWithBaseline(const std::vector<YardstickRow>& baseline,
                                       const std::vector<YardstickRow>& current,
                                       const std::vector<double>& sted_targets,
                                       double breakdown_sted) {
  BaselineComparison comparison;
  comparison.curve = "dmc/" + current.front().operator_name;
  const std::vector<RdSample> baseline_sted = ParetoFront(StedSamples(baseline));
  const std::vector<RdSample> current_sted = ParetoFront(StedSamples(current));
  comparison.bd_rate_sted = BjontegaardDeltaRate(baseline_sted, current_sted);
  comparison.bd_rate_kg =
      BjontegaardDeltaRate(ParetoFront(KgSamples(baseline)), ParetoFront(KgSamples(current)));
  for (const double target : sted_targets) {
    comparison.targets.push_back({target, RateForDistortion(baseline_sted, target),
                                  RateForDistortion(current_sted, target)});
  }
  comparison.baseline_near = NearestToSted(baseline, breakdown_sted);
  comparison.current_near = NearestToSted(current, breakdown_sted);
  return comparison;
}

std::string ComparisonMarkdown(const std::string& sequence,
                               const std::vector<BaselineComparison>& comparisons,
                               double breakdown_sted) {
  std::string md = fmt::format("## Against the baseline's `{}`\n\n", sequence);
  if (comparisons.empty()) return md + "No dmc curve to compare.\n\n";
  md += "| curve | BD-rate (STED) | BD-rate (KG) |";
  for (const auto& target : comparisons.front().targets) {
    md += fmt::format(" bpfv @ STED {:g} (baseline) |", target.sted);
  }
  md += "\n|---|---:|---:|";
  for (size_t i = 0; i < comparisons.front().targets.size(); ++i) md += "---:|";
  md += "\n";
  for (const BaselineComparison& c : comparisons) {
    md += fmt::format("| {} | {} | {} |", c.curve, PercentCell(c.bd_rate_sted),
                      PercentCell(c.bd_rate_kg));
    for (const auto& target : c.targets) {
      md += fmt::format(" {} ({}) |", RateCell(target.current), RateCell(target.baseline));
    }
    md += "\n";
  }
  md += fmt::format(
      "\nBytes per element at the ladder point nearest STED {:g}, percent of the stream:\n\n",
      breakdown_sted);
  md +=
      "| curve | point | residual bits | STED | bpfv | rank | residuals | basis | operator | "
      "connectivity | anchors | mean | header |\n";
  md += "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const auto row = [&](const std::string& curve, const char* which, const YardstickRow& r) {
    md += fmt::format(
        "| {} | {} | {:.4g} | {:.4g} | {:.4g} | {} | {} | {} | {} | {} | {} | {} | {} |\n", curve,
        which, r.residual_bits, r.sted, r.bpfv, r.rank, Percent(r.residual_bytes, r.bytes),
        Percent(r.basis_bytes, r.bytes), Percent(r.operator_bytes, r.bytes),
        Percent(r.connectivity_bytes, r.bytes), Percent(r.anchor_bytes, r.bytes),
        Percent(r.mean_bytes, r.bytes), Percent(r.header_bytes, r.bytes));
  };
  for (const BaselineComparison& c : comparisons) {
    row(c.curve, "current", c.current_near);
    row(c.curve, "baseline", c.baseline_near);
  }
  md +=
      "\nBD-rate: Bjøntegaard delta rate against the baseline's curve over the STED (or KG) range "
      "both cover; negative means fewer bits. bpfv at a target STED is interpolated log–log "
      "between the efficient points around it (\"≤ r\": the cheapest point already meets it, "
      "\"> r\": no point reaches it).\n\n";
  return md;
}

}  // namespace dmc::sweep

// dmc sweep: rate–distortion curves of dmc (one per Laplace operator) and of the baseline codecs
// (Draco per frame, meshoptimizer + zstd, quantised deltas + zstd), all decoded and measured with
// the same metrics; writes rd.csv, rd_sted.svg, rd_kg.svg, summary.md and yardstick.csv, and with
// --baseline compares the dmc curves with a committed baseline's (baseline.md).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "dmc/decoder.h"
#include "dmc/io.h"
#include "sweep/report.h"
#include "sweep/sweep.h"
#include "sweep/yardstick.h"

namespace dmc::cli {
namespace {

struct SweepArgs {
  std::string input;
  std::string output;
  std::string connectivity;
  int max_frames = 0;
  std::vector<std::string> operators = sweep::SweepOptions().operators;
  std::vector<std::string> baselines = {"draco", "meshopt", "zstd"};
  std::vector<double> sted_targets = {0.01, 0.02, 0.05};
  std::string baseline;  // yardstick CSV to compare with; empty = none
  std::string sequence;  // the name in the yardstick; empty = SequenceNameOf(input)
  double breakdown_sted = 0.02;
  bool range_given = false;  // --points, --min- or --max-residual-bits on the command line
  sweep::SweepOptions options;
  std::vector<std::string> encoder_settings;  // --encoder-option NAME=VALUE
  GltfReadFlags gltf;
  bool json = false;
};

std::string Join(const std::vector<std::string>& items) {
  std::string joined;
  for (const std::string& item : items) joined += (joined.empty() ? "" : ",") + item;
  return joined;
}

// `text` as one shell word: unchanged when it is plain, else single-quoted (glTF mesh and
// animation names may hold spaces).
std::string ShellWord(const std::string& text) {
  const bool plain = !text.empty() && std::all_of(text.begin(), text.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || c == '_' || c == '-' || c == '.' || c == '/';
  });
  if (plain) return text;
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// The equivalent command line, written into summary.md so a sweep can be rerun.
std::string CommandLine(const SweepArgs& args) {
  const sweep::SweepOptions& o = args.options;
  std::string targets;
  for (const double target : args.sted_targets) {
    targets += (targets.empty() ? "" : ",") + fmt::format("{:g}", target);
  }
  std::string line = fmt::format(
      "dmc sweep {} -o {} --operators {} --baselines {} --points {} --min-residual-bits {:g} "
      "--max-residual-bits {:g} --basis-bits {} --effort {} --min-baseline-bits {} "
      "--max-baseline-bits {} --sted-targets {}",
      args.input, args.output, args.operators.empty() ? "none" : Join(args.operators),
      args.baselines.empty() ? "none" : Join(args.baselines), o.points, o.min_residual_bits,
      o.max_residual_bits, o.basis_bits, o.effort, o.min_baseline_bits, o.max_baseline_bits,
      targets);
  if (!o.ladder.empty()) {
    std::string rungs;
    for (const double bits : o.ladder)
      rungs += (rungs.empty() ? "" : ",") + fmt::format("{:g}", bits);
    line += " --ladder " + rungs;
  }
  line += " --sequence " + ShellWord(args.sequence);
  if (!args.baseline.empty()) {
    line += fmt::format(" --baseline {} --breakdown-sted {:g}", ShellWord(args.baseline),
                        args.breakdown_sted);
  }
  if (args.max_frames > 0) line += fmt::format(" --max-frames {}", args.max_frames);
  if (!args.connectivity.empty()) line += " --connectivity " + args.connectivity;
  const GltfReadOptions& gltf = args.gltf.options;
  if (gltf.frame_rate > 0.0) line += fmt::format(" --gltf-fps {:g}", gltf.frame_rate);
  if (!gltf.mesh.empty()) line += " --gltf-mesh " + ShellWord(gltf.mesh);
  if (!gltf.animation.empty()) line += " --gltf-animation " + ShellWord(gltf.animation);
  if (gltf.weld) line += " --gltf-weld";
  return line;
}

// "none" (or nothing) selects no item.
std::vector<std::string> WithoutNone(std::vector<std::string> items) {
  std::erase_if(items, [](const std::string& item) { return item == "none" || item.empty(); });
  return items;
}

Status WriteText(const std::filesystem::path& path, const std::string& text) {
  return WriteFileAtomically(
      path, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

nlohmann::json PointJson(const sweep::RdPoint& p) {
  const auto optional_int = [](int value) -> nlohmann::json {
    return value < 0 ? nlohmann::json(nullptr) : nlohmann::json(value);
  };
  return {{"codec", p.codec},
          {"operator",
           p.operator_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(p.operator_name)},
          {"rank", optional_int(p.rank)},
          {"basis_bits", optional_int(p.basis_bits)},
          {"residual_bits", p.residual_bits},
          {"anchors", optional_int(p.anchors)},
          {"segments", optional_int(p.segments)},
          {"segment_operators", p.segment_operators},
          {"bytes", p.bytes},
          {"breakdown",
           {{"header", p.header_bytes},
            {"connectivity", p.connectivity_bytes},
            {"mean", p.mean_bytes},
            {"basis", p.basis_bytes},
            {"operator", p.operator_bytes},
            {"anchors", p.anchor_bytes},
            {"residuals", p.residual_bytes}}},
          {"bpfv", p.bpfv},
          {"kg", p.kg},
          {"sted", p.sted},
          {"encode_s", p.encode_s},
          {"decode_s", p.decode_s}};
}

nlohmann::json RateJson(const sweep::RateAtTarget& rate) {
  const char* kind = rate.kind == sweep::RateAtTarget::Kind::kInterpolated ? "interpolated"
                     : rate.kind == sweep::RateAtTarget::Kind::kBelowRange ? "below-range"
                                                                           : "above-range";
  return {{"bpfv", rate.rate}, {"kind", kind}};
}

nlohmann::json RowJson(const sweep::YardstickRow& r) {
  return {{"residual_bits", r.residual_bits},
          {"rank", r.rank},
          {"segment_operators", r.segment_operators},
          {"bytes", r.bytes},
          {"bpfv", r.bpfv},
          {"kg", r.kg},
          {"sted", r.sted},
          {"breakdown",
           {{"header", r.header_bytes},
            {"connectivity", r.connectivity_bytes},
            {"mean", r.mean_bytes},
            {"basis", r.basis_bytes},
            {"operator", r.operator_bytes},
            {"anchors", r.anchor_bytes},
            {"residuals", r.residual_bytes}}}};
}

nlohmann::json ComparisonJson(const sweep::BaselineComparison& c) {
  const auto optional = [](const std::optional<double>& value) {
    return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
  };
  nlohmann::json targets = nlohmann::json::array();
  for (const auto& target : c.targets) {
    targets.push_back({{"sted", target.sted},
                       {"current", RateJson(target.current)},
                       {"baseline", RateJson(target.baseline)}});
  }
  return {{"curve", c.curve},
          {"bd_rate_sted", optional(c.bd_rate_sted)},
          {"bd_rate_kg", optional(c.bd_rate_kg)},
          {"targets", targets},
          {"current_near", RowJson(c.current_near)},
          {"baseline_near", RowJson(c.baseline_near)}};
}

// The baseline file, parsed.
StatusOr<sweep::Yardstick> ReadBaseline(const std::string& path) {
  DMC_ASSIGN_OR_RETURN(const std::vector<uint8_t> bytes, ReadFileBytes(path));
  StatusOr<sweep::Yardstick> yardstick = sweep::ParseYardstick(
      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  if (!yardstick.ok()) {
    return Status(yardstick.status().code(), path + ": " + yardstick.status().message());
  }
  return yardstick;
}

int RunSweep(SweepArgs args) {
  args.operators = WithoutNone(args.operators);
  args.baselines = WithoutNone(args.baselines);
  sweep::SweepOptions options = args.options;
  options.operators = args.operators;
  options.baselines.clear();
  for (const std::string& name : args.baselines) {
    StatusOr<sweep::BaselineKind> kind = sweep::ParseBaseline(name);
    if (!kind.ok()) return ReportError("sweep", kind.status(), args.json);
    options.baselines.push_back(*kind);
  }
  for (const std::string& setting : args.encoder_settings) {
    if (Status set = sweep::SetEncoderOption(&options.encoder, setting); !set.ok()) {
      return ReportError("sweep", set, args.json);
    }
  }
  // Everything that can be checked before the (long) run.
  if (Status valid = sweep::ValidateSweepOptions(options); !valid.ok()) {
    return ReportError("sweep", valid, args.json);
  }
  for (const double target : args.sted_targets) {
    if (!(target > 0.0)) {
      return ReportError("sweep", InvalidArgumentError("--sted-targets must be positive"),
                         args.json);
    }
  }
  if (!(args.breakdown_sted > 0.0)) {
    return ReportError("sweep", InvalidArgumentError("--breakdown-sted must be positive"),
                       args.json);
  }
  if (args.sequence.empty()) args.sequence = sweep::SequenceNameOf(args.input);
  if (args.sequence.empty() || args.sequence.find_first_of(",\n\r") != std::string::npos) {
    return ReportError("sweep",
                       InvalidArgumentError("--sequence must be a name without commas or line "
                                            "breaks, got '" +
                                            args.sequence + "'"),
                       args.json);
  }
  std::optional<sweep::Yardstick> baseline;
  if (!args.baseline.empty()) {
    StatusOr<sweep::Yardstick> read = ReadBaseline(args.baseline);
    if (!read.ok()) return ReportError("sweep", read.status(), args.json);
    baseline = std::move(*read);
  }
  const std::filesystem::path output(args.output);
  std::error_code error;
  std::filesystem::create_directories(output, error);
  if (error || !std::filesystem::is_directory(output)) {
    return ReportError("sweep",
                       IoError("cannot create output directory " + args.output + ": " +
                               (error ? error.message() : "a file is in the way")),
                       args.json);
  }

  WarnIfGltfOptionsUnused("sweep", args.gltf, {args.input});
  ReadOptions read_options;
  read_options.connectivity = args.connectivity;
  read_options.max_frames = args.max_frames;
  read_options.gltf = args.gltf.options;
  ReadReport read_report;
  StatusOr<MeshSequence> sequence = ReadSequence(args.input, read_options, &read_report);
  if (!sequence.ok()) return ReportError("sweep", sequence.status(), args.json);
  if (!args.json) {
    for (const std::string& warning : read_report.warnings) ReportWarning("sweep", warning);
    fmt::print("{}: {} frames x {} vertices\n", args.input, sequence->frame_count(),
               sequence->vertex_count());
  }
  std::vector<sweep::YardstickRow> baseline_curve;
  if (baseline) {
    StatusOr<std::vector<sweep::YardstickRow>> curve = sweep::BaselineCurve(
        *baseline, args.sequence, sequence->vertex_count(), sequence->frame_count());
    if (!curve.ok()) {
      return ReportError(
          "sweep", Status(curve.status().code(), args.baseline + ": " + curve.status().message()),
          args.json);
    }
    baseline_curve = std::move(*curve);
    // The baseline's own ladder, unless the command line gives one.
    if (options.ladder.empty() && !args.range_given) {
      for (const sweep::YardstickRow& row : baseline_curve) {
        options.ladder.push_back(row.residual_bits);
      }
      args.options.ladder = options.ladder;
    }
  }

  std::optional<Progress> progress;
  const auto on_point = [&](const sweep::RdPoint* point, const std::string& warning, int done,
                            int total) {
    if (!progress) progress.emplace("sweep", total);
    progress->Update(done);
    if (!warning.empty()) ReportWarning("sweep", warning);
    if (point != nullptr && !args.json) {
      // A ddl point the fallback coded (in part) with another operator says so.
      const bool other_operator =
          !point->segment_operators.empty() &&
          point->segment_operators != fmt::format("{}:{}", point->operator_name, point->segments);
      fmt::print(
          "  {:<16} bits {:5.2f}  rank {:>3}  {:8.4f} bpfv  KG {:8.4f}  STED {:8.5f}  "
          "encode {:6.2f} s  decode {:6.3f} s{}\n",
          point->Curve(), point->residual_bits,
          point->rank < 0 ? std::string("-") : std::to_string(point->rank), point->bpfv, point->kg,
          point->sted, point->encode_s, point->decode_s,
          other_operator ? "  coded as " + point->segment_operators : "");
      std::fflush(stdout);
    }
  };
  StatusOr<sweep::SweepResult> result = sweep::RunSweep(*sequence, options, on_point);
  progress.reset();
  if (!result.ok()) return ReportError("sweep", result.status(), args.json);

  sweep::SummaryContext context;
  context.input = args.input;
  context.command = CommandLine(args);
  context.vertices = sequence->vertex_count();
  context.frames = sequence->frame_count();
  context.sted = options.sted;
  context.sted_targets = args.sted_targets;
  context.warnings = result->warnings;
  context.default_point = result->default_point;
  const std::vector<sweep::YardstickRow> rows =
      sweep::YardstickRows(args.sequence, sequence->vertex_count(), sequence->frame_count(),
                           options.effort, result->points);
  std::vector<sweep::BaselineComparison> comparisons;
  for (const std::string& name : args.operators) {
    std::vector<sweep::YardstickRow> curve;
    for (const sweep::YardstickRow& row : rows) {
      if (row.operator_name == name) curve.push_back(row);
    }
    if (!baseline_curve.empty() && !curve.empty()) {
      comparisons.push_back(sweep::CompareWithBaseline(baseline_curve, curve, args.sted_targets,
                                                       args.breakdown_sted));
    }
  }
  const std::string comparison_md =
      baseline ? sweep::ComparisonMarkdown(args.sequence, comparisons, args.breakdown_sted) : "";
  const std::string subtitle = fmt::format("{}: {} vertices × {} frames",
                                           sequence->name.empty() ? args.input : sequence->name,
                                           sequence->vertex_count(), sequence->frame_count());
  std::vector<std::pair<std::string, std::string>> files = {
      {"rd.csv", sweep::RdCsv(result->points, result->default_point)},
      {"rd_sted.svg", sweep::RenderSvgPlot(sweep::RdPlot(result->points, sweep::RdMetric::kSted,
                                                         subtitle, result->default_point))},
      {"rd_kg.svg", sweep::RenderSvgPlot(sweep::RdPlot(result->points, sweep::RdMetric::kKg,
                                                       subtitle, result->default_point))},
      {"summary.md", sweep::SummaryMarkdown(result->points, context)},
      {"yardstick.csv",
       sweep::YardstickCsv({{"input", args.input}, {"command", context.command}}, rows)},
  };
  if (baseline) {
    files.emplace_back("baseline.md",
                       fmt::format("Baseline: `{}`\n\n{}", args.baseline, comparison_md));
  }
  for (const auto& [name, text] : files) {
    if (Status written = WriteText(output / name, text); !written.ok()) {
      return ReportError("sweep", written, args.json);
    }
  }

  if (args.json) {
    nlohmann::json points = nlohmann::json::array();
    for (const sweep::RdPoint& point : result->points) points.push_back(PointJson(point));
    nlohmann::json compared = nlohmann::json::array();
    for (const sweep::BaselineComparison& c : comparisons) compared.push_back(ComparisonJson(c));
    PrintJson({{"input", args.input},
               {"sequence", args.sequence},
               {"vertices", sequence->vertex_count()},
               {"frames", sequence->frame_count()},
               {"output", args.output},
               {"points", points},
               {"default_point", result->default_point ? PointJson(*result->default_point)
                                                       : nlohmann::json(nullptr)},
               {"baseline", baseline ? nlohmann::json(args.baseline) : nlohmann::json(nullptr)},
               {"comparisons", compared},
               {"warnings", result->warnings}});
    return 0;
  }
  fmt::print("\n{}", sweep::RateTargetTable(result->points, context));
  if (baseline) fmt::print("{}", comparison_md);
  fmt::print(
      "wrote {0}/rd.csv, {0}/rd_sted.svg, {0}/rd_kg.svg, {0}/summary.md, {0}/yardstick.csv{1}\n",
      args.output, baseline ? fmt::format(", {}/baseline.md", args.output) : "");
  return 0;
}

}  // namespace

Command AddSweepCommand(CLI::App& parent) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* app = parent.add_subcommand(
      "sweep",
      "Rate-distortion sweep: encode, decode and measure INPUT at a ladder of rates with dmc "
      "(one curve per operator) and with baseline codecs; writes DIR/rd.csv, DIR/rd_sted.svg, "
      "DIR/rd_kg.svg, DIR/summary.md and DIR/yardstick.csv (the dmc points as rows of the "
      "rate-distortion yardstick); with --baseline also DIR/baseline.md");
  app->add_option("-i,--input,INPUT", args->input,
                  "Sequence: a directory of .obj/.off/.ply frames, a glob, a .pc2 cache, or a "
                  ".glb/.gltf animation")
      ->required();
  app->add_option("-o,--output", args->output, "Output directory (created if missing)")->required();
  app->add_option("--connectivity", args->connectivity, "PC2 only: mesh giving the triangles");
  app->add_option("--max-frames", args->max_frames, "Sweep only the first N frames (0 = all)")
      ->capture_default_str();
  app->add_option("--operators", args->operators,
                  "Comma-separated codec operators, one curve each (or 'none')")
      ->delimiter(',')
      ->capture_default_str();
  app->add_option("--baselines", args->baselines,
                  "Comma-separated baselines among draco, meshopt, zstd (or 'none')")
      ->delimiter(',')
      ->capture_default_str();
  sweep::SweepOptions& o = args->options;
  CLI::Option* points =
      app->add_option("--points", o.points, "Ladder rungs per curve (>= 2)")->capture_default_str();
  CLI::Option* min_bits = app->add_option("--min-residual-bits", o.min_residual_bits,
                                          "dmc ladder: coarsest residual step = diagonal * 2^-bits")
                              ->capture_default_str();
  CLI::Option* max_bits = app->add_option("--max-residual-bits", o.max_residual_bits,
                                          "dmc ladder: finest residual step = diagonal * 2^-bits")
                              ->capture_default_str();
  app->add_option("--ladder", o.ladder,
                  "dmc ladder given rung by rung: comma-separated residual bits (replaces "
                  "--points/--min-/--max-residual-bits for dmc; with --baseline the default is "
                  "the baseline's ladder for the sequence)")
      ->delimiter(',');
  app->add_option("--baseline", args->baseline,
                  "Yardstick CSV (bench/rd/baseline.csv) to compare the dmc curves with: BD-rates "
                  "in STED and KG against its curve for the sequence, the bpfv at each STED "
                  "target, and the bytes per element near --breakdown-sted");
  app->add_option("--sequence", args->sequence,
                  "The sequence's name in the yardstick (default: the input directory's name, or "
                  "the file's name without extension)");
  app->add_option("--breakdown-sted", args->breakdown_sted,
                  "With --baseline: the bytes per element of the points nearest this STED")
      ->capture_default_str();
  app->add_option("--basis-bits", o.basis_bits,
                  "dmc basis quantisation bits (0 = clamp(residual bits, 10, 16) per rung)")
      ->capture_default_str();
  app->add_option("--effort", o.effort,
                  "dmc encoder search effort 0..9 (as dmc encode --effort; 8 = the exhaustive "
                  "search of earlier versions)")
      ->capture_default_str();
  app->add_option("--encoder-option", args->encoder_settings,
                  "NAME=VALUE: a dmc encoder option for every dmc point, by its name in dmc "
                  "encode's flags with '_' for '-' (e.g. rank_threshold=100, "
                  "residual_rdo_lambda=0); repeatable. The ladder's own (operator, residual "
                  "bits and step, basis bits, effort) are set by the options above");
  app->add_option("--min-baseline-bits", o.min_baseline_bits,
                  "Baselines: coarsest position quantisation bits")
      ->capture_default_str();
  app->add_option("--max-baseline-bits", o.max_baseline_bits,
                  "Baselines: finest position quantisation bits")
      ->capture_default_str();
  app->add_option("--sted-targets", args->sted_targets,
                  "Comma-separated STED values for the rate table of summary.md")
      ->delimiter(',')
      ->capture_default_str();
  app->add_option("--sted-width", o.sted.width, "STED neighbourhood width w")
      ->capture_default_str();
  app->add_option("--sted-dt", o.sted.dt, "STED frame distance dt")->capture_default_str();
  app->add_option("--sted-window", o.sted.window, "STED speed window s")->capture_default_str();
  app->add_option("--sted-c", o.sted.c, "STED weight c of the temporal part")
      ->capture_default_str();
  AddGltfReadOptions(app, &args->gltf);
  app->add_flag("--json", args->json, "Print the points as JSON instead of the text report");
  return {app, [args, points, min_bits, max_bits] {
            args->range_given = points->count() + min_bits->count() + max_bits->count() > 0;
            return RunSweep(*args);
          }};
}

}  // namespace dmc::cli

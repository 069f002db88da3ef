// dmc encode: compress a mesh sequence to a .dmc stream and report rate and distortion.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "dmc/encoder.h"
#include "dmc/io.h"

namespace dmc::cli {
namespace {

struct EncodeArgs {
  std::string input;
  std::string output;
  std::string connectivity;
  EncoderOptions options;
  GltfReadFlags gltf;
  bool no_measure = false;
  bool no_ddl_fallback = false;
  bool no_rank_search = false;
  bool json = false;
  bool progress = false;
};

// Encodes with EncodeStreaming: a PC2 cache is read segment by segment (memory bounded by one
// segment, also under rate control, which then reads the cache once per trial); other inputs are
// read whole first and encoded several segments at a time. The bytes are Encode()'s either way.
Status EncodeInput(const EncodeArgs& args, const EncoderOptions& options, EncodeReport& report) {
  std::optional<Progress> progress;
  std::string progress_label;
  auto show = [&](const std::string& label, int done, int total) {
    if (label != progress_label) {
      progress.reset();  // finishes the previous stage's line
      progress.emplace(label, total, args.progress);
      progress_label = label;
    }
    progress->Update(done);
  };
  WarnIfGltfOptionsUnused("encode", args.gltf, {args.input});
  if (IsPc2Path(args.input)) {
    std::vector<std::string> warnings;
    DMC_ASSIGN_OR_RETURN(std::unique_ptr<FrameSource> source,
                         OpenPc2FrameSource(args.input, args.connectivity, &warnings));
    for (const auto& warning : warnings) ReportWarning("encode", warning);
    StreamingEncodeOptions streaming;
    streaming.progress = [&](EncodeStage stage, int done, int total) {
      show(std::string(EncodeStageName(stage)), done, total);
    };
    return EncodeStreaming(*source, args.output, options, &report, streaming);
  }
  ReadOptions read_options;
  read_options.connectivity = args.connectivity;
  read_options.gltf = args.gltf.options;
  read_options.progress = [&](int done, int total) { show("reading", done, total); };
  ReadReport read_report;
  DMC_ASSIGN_OR_RETURN(const MeshSequence sequence,
                       ReadSequence(args.input, read_options, &read_report));
  for (const auto& warning : read_report.warnings) ReportWarning("encode", warning);
  SequenceFrameSource source(sequence);
  StreamingEncodeOptions streaming;
  streaming.segments_in_flight =
      static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  streaming.progress = [&](EncodeStage stage, int done, int total) {
    show(std::string(EncodeStageName(stage)), done, total);
  };
  return EncodeStreaming(source, args.output, options, &report, streaming);
}

// "ddl", or "ddl (segments: ddl 3, kirchhoff 1)" when some segment used another operator.
std::string OperatorSummary(const std::string& requested,
                            const std::vector<std::string>& segment_operators) {
  std::map<std::string, int> counts;
  for (const std::string& name : segment_operators) ++counts[name];
  if (counts.empty() || (counts.size() == 1 && counts.begin()->first == requested)) {
    return requested;
  }
  std::string summary;
  for (const auto& [name, count] : counts) {
    summary += fmt::format("{}{} {}", summary.empty() ? "" : ", ", name, count);
  }
  return requested + " (segments: " + summary + ")";
}

int RunEncode(const EncodeArgs& args) {
  EncoderOptions options = args.options;
  options.measure = !args.no_measure;
  options.ddl_fallback = !args.no_ddl_fallback;
  options.rank_search = !args.no_rank_search;
  EncodeReport report;
  const Status status = EncodeInput(args, options, report);
  if (!status.ok()) return ReportError("encode", status, args.json);

  const nlohmann::json breakdown = {
      {"header", report.header_bytes},     {"connectivity", report.connectivity_bytes},
      {"mean", report.mean_bytes},         {"basis", report.basis_bytes},
      {"operator", report.operator_bytes}, {"anchors", report.anchor_bytes},
      {"residuals", report.residual_bytes}};
  if (args.json) {
    nlohmann::json out = {{"bpfv", report.bpfv},
                          {"bytes", report.bytes},
                          {"frames", report.frames},
                          {"vertices", report.vertices},
                          {"seconds", report.seconds},
                          {"breakdown", breakdown},
                          {"operator", options.operator_name},
                          {"rank", report.rank},
                          {"anchors", report.anchors},
                          {"segments", report.segments},
                          {"segment_operators", report.segment_operators},
                          {"residual_step", report.residual_step}};
    if (report.measured) {
      out["kg"] = report.distortion.kg;
      out["sted"] = report.distortion.sted;
      out["sted_s"] = report.distortion.sted_s;
      out["sted_t"] = report.distortion.sted_t;
      out["rmse_rel"] = report.distortion.rmse_rel;
      out["max_error"] = report.distortion.max_error;
    } else {
      out["kg"] = nullptr;
      out["sted"] = nullptr;
    }
    PrintJson(out);
    return 0;
  }
  const double scale = 8.0 / (static_cast<double>(report.frames) * report.vertices);
  fmt::print("{}: {} frames x {} vertices -> {} bytes, {:.4f} bpfv ({:.2f} s)\n", args.output,
             report.frames, report.vertices, report.bytes, report.bpfv, report.seconds);
  fmt::print("  operator {}, rank {}, {} anchors, {} segment(s), residual step {:.4g}\n",
             OperatorSummary(options.operator_name, report.segment_operators), report.rank,
             report.anchors, report.segments, report.residual_step);
  if (report.measured) {
    fmt::print("  KG {:.4f}  STED {:.5f} (spatial {:.5f}, temporal {:.5f})  RMSE/diag {:.3g}\n",
               report.distortion.kg, report.distortion.sted, report.distortion.sted_s,
               report.distortion.sted_t, report.distortion.rmse_rel);
  }
  fmt::print("  bpfv by element:");
  for (const auto& [name, bytes] : breakdown.items()) {
    fmt::print(" {} {:.4f}", name, bytes.get<double>() * scale);
  }
  fmt::print("\n");
  return 0;
}

}  // namespace

Command AddEncodeCommand(CLI::App& parent) {
  auto args = std::make_shared<EncodeArgs>();
  CLI::App* app = parent.add_subcommand("encode", "Compress a mesh sequence to a .dmc stream");
  app->add_option("INPUT", args->input,
                  "Sequence: frame directory, glob, mesh file, .pc2 or .glb/.gltf")
      ->required();
  app->add_option("-o,--output", args->output, "Output .dmc file")->required();
  app->add_option("--connectivity", args->connectivity, "PC2 only: mesh giving the triangles");
  AddGltfReadOptions(app, &args->gltf);
  EncoderOptions& o = args->options;
  app->add_option(
         "--operator", o.operator_name,
         "Laplace operator: ddl, tutte, kirchhoff, cotan, cotan-area, cotan-sym, mean-value")
      ->capture_default_str();
  app->add_option("--rank", o.rank, "PCA basis vectors per segment (0 = automatic)")
      ->capture_default_str();
  app->add_option("--rank-threshold", o.rank_threshold,
                  "Automatic rank: keep components with eigenvalue > T * V * step^2")
      ->capture_default_str();
  app->add_option("--basis-bits", o.basis_bits, "Basis quantisation bits")->capture_default_str();
  app->add_option("--residual-bits", o.residual_bits,
                  "Residual step = bounding-box diagonal * 2^-bits")
      ->capture_default_str();
  app->add_option("--residual-step", o.residual_step, "Absolute residual step (overrides bits)");
  app->add_option("--anchors", o.anchors, "Anchor vertices per segment (-1 = automatic)")
      ->capture_default_str();
  app->add_option("--anchor-step-ratio", o.anchor_step_ratio,
                  "Anchor quantisation step relative to the residual step")
      ->capture_default_str();
  app->add_option("--segment-frames", o.segment_frames, "Maximum frames per segment (0 = default)")
      ->capture_default_str();
  app->add_option("--reference-bits", o.reference_bits,
                  "Geometric operators: reference frame step = diagonal * 2^-bits")
      ->capture_default_str();
  app->add_option("--weight-bits", o.weight_bits, "DDL weight step 2^-bits")->capture_default_str();
  app->add_option("--ddl-mu", o.ddl_regularization, "DDL Tikhonov pull toward Tutte")
      ->capture_default_str();
  app->add_option("--ddl-dead-zone", o.ddl_dead_zone,
                  "DDL weights this close to their prediction (weight units) are sent as "
                  "predicted: 0.5 = rounding, inf = predicted only, 0 = choose per segment")
      ->capture_default_str();
  app->add_flag("--no-ddl-fallback", args->no_ddl_fallback,
                "ddl: always code the fitted weights, never kirchhoff, tutte or mean-value for a "
                "segment where they have the lower rate at equal STED");
  app->add_flag("--no-rank-search", args->no_rank_search,
                "ddl with an automatic rank: code each segment at the rank of --rank-threshold "
                "only, not also at the lower ranks of 2 and 4 times it");
  app->add_flag("--uniform-weight-prediction", o.weight_prediction_uniform,
                "DDL weights predicted by the thesis's uniform share, not the degree reference");
  app->add_option("--target-bpfv", o.target_bpfv, "Search parameters for this rate");
  app->add_option("--target-sted", o.target_sted, "Search parameters for this STED");
  app->add_flag("--allow-reorder", o.allow_reorder,
                "Let the output use the codec's vertex order (smaller connectivity)");
  app->add_flag("--no-measure", args->no_measure, "Skip decoding and measuring KG/STED");
  app->add_flag("--json", args->json, "Machine-readable output");
  app->add_flag("--progress", args->progress,
                "Show progress on stderr even when it is not a terminal");
  return {app, [args] { return RunEncode(*args); }};
}

}  // namespace dmc::cli

// dmc encode: compress a mesh sequence to a .dmc stream and report rate and distortion.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <variant>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "dmc/encoder.h"
#include "dmc/encoder_options.h"
#include "dmc/io.h"

namespace dmc::cli {
namespace {

struct EncodeArgs {
  std::string input;
  std::string output;
  std::string connectivity;
  EncoderOptions options;
  std::vector<std::string> given;  // the option table names given on the command line
  GltfReadFlags gltf;
  bool json = false;
  bool progress = false;
  bool no_scene = false;
};

// Encodes with EncodeStreaming: a PC2 cache is read segment by segment (memory bounded by one
// segment, also under rate control, which then reads the cache once or twice per trial); other
// inputs are read whole first and encoded several segments at a time. The bytes are Encode()'s
// either way.
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
  if (IsGltfPath(args.input) && !args.no_scene) {
    // What the glTF holds besides motion travels in the stream's scene chunk.
    DMC_ASSIGN_OR_RETURN(streaming.scene, BuildGltfScene(args.input, read_options, read_report,
                                                         sequence.vertex_count()));
  }
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

// What each segment's header says, as `dmc info` of the stream shows it.
nlohmann::json SegmentDetailsJson(const EncodeReport& report) {
  nlohmann::json segments = nlohmann::json::array();
  for (const EncodeReport::Segment& segment : report.segment_details) {
    segments.push_back({{"first_frame", segment.first_frame},
                        {"frames", segment.frames},
                        {"operator", segment.operator_name},
                        {"rank", segment.rank},
                        {"anchors", segment.anchors},
                        {"residual_step", segment.residual_step}});
  }
  return segments;
}

// One line per segment when one was coded otherwise than the summary says (another operator, so
// another step, or another rank); at most kListedSegments of them.
void PrintSegmentDetails(const EncodeReport& report, const std::string& requested) {
  constexpr size_t kListedSegments = 16;
  const auto& segments = report.segment_details;
  const bool uniform = std::all_of(segments.begin(), segments.end(), [&](const auto& segment) {
    return segment.operator_name == requested && segment.rank == segments.front().rank &&
           segment.residual_step == segments.front().residual_step;
  });
  if (uniform) return;
  for (size_t s = 0; s < segments.size() && s < kListedSegments; ++s) {
    const EncodeReport::Segment& segment = segments[s];
    fmt::print("  segment {}, frames {}-{}: {}, rank {}, {} anchors, residual step {:.4g}\n", s,
               segment.first_frame, segment.first_frame + segment.frames - 1, segment.operator_name,
               segment.rank, segment.anchors, segment.residual_step);
  }
  if (segments.size() > kListedSegments) {
    fmt::print("  ... {} more segments (--json lists them all)\n",
               segments.size() - kListedSegments);
  }
}

int RunEncode(const EncodeArgs& args) {
  const EncoderOptions& options = args.options;
  // In the options 0 means "no target"; a target given on the command line must be one.
  for (const auto& [name, value] : {std::pair{"target_bpfv", options.target_bpfv},
                                    std::pair{"target_sted", options.target_sted}}) {
    if (std::find(args.given.begin(), args.given.end(), name) != args.given.end() && value <= 0.0) {
      return ReportError(
          "encode",
          InvalidArgumentError(fmt::format("{} must be > 0 (got {}); leave it out to encode at a "
                                           "fixed step",
                                           SpellOption(name, OptionSpelling::kCliFlag), value)),
          args.json);
    }
  }
  // Checked here as well as by the encoder so that the message names the flags.
  if (const Status valid = ValidateOptions(options, OptionSpelling::kCliFlag); !valid.ok()) {
    return ReportError("encode", valid, args.json);
  }
  if (const Status valid = CheckGivenSwitches(options, args.given, OptionSpelling::kCliFlag);
      !valid.ok()) {
    return ReportError("encode", valid, args.json);
  }
  if (const Status distinct = RefuseOutputThatIsAnInput(args.output, args.input, args.connectivity);
      !distinct.ok()) {
    return ReportError("encode", distinct, args.json);
  }
  if (options.fps > 0 && IsGltfPath(args.input)) {
    // A glTF animation has its own clock; --fps would silently retime it.
    return ReportError("encode",
                       InvalidArgumentError("--fps sets the rate of inputs that have none; a glTF "
                                            "animation is sampled at --gltf-fps instead"),
                       args.json);
  }
  EncodeReport report;
  const Status status = EncodeInput(args, options, report);
  if (!status.ok()) return ReportError("encode", status, args.json);

  const nlohmann::json breakdown = {
      {"header", report.header_bytes},      {"connectivity", report.connectivity_bytes},
      {"mean", report.mean_bytes},          {"basis", report.basis_bytes},
      {"operator", report.operator_bytes},  {"anchors", report.anchor_bytes},
      {"residuals", report.residual_bytes}, {"scene", report.scene_bytes}};
  if (args.json) {
    nlohmann::json out = {{"bpfv", report.bpfv},
                          {"positions_bpfv", report.positions_bpfv},
                          {"bytes", report.bytes},
                          {"frames", report.frames},
                          {"vertices", report.vertices},
                          {"seconds", report.seconds},
                          {"breakdown", breakdown},
                          {"operator", options.operator_name},
                          {"effort", options.effort},
                          {"rank", report.rank},
                          {"anchors", report.anchors},
                          {"segments", report.segments},
                          {"segment_operators", report.segment_operators},
                          {"residual_step", report.residual_step},
                          {"segment_details", SegmentDetailsJson(report)}};
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
    if (!report.not_measured_reason.empty()) out["not_measured"] = report.not_measured_reason;
    PrintJson(out);
    return 0;
  }
  const double scale = 8.0 / (static_cast<double>(report.frames) * report.vertices);
  fmt::print("{}: {} frames x {} vertices -> {} bytes, {:.4f} bpfv ({:.2f} s)\n", args.output,
             report.frames, report.vertices, report.bytes, report.bpfv, report.seconds);
  // The step as the first segment's header has it (a kirchhoff segment's is scaled).
  const double step = report.segment_details.empty() ? report.residual_step
                                                     : report.segment_details.front().residual_step;
  fmt::print("  operator {}, rank {}, {} anchors, {} segment(s), residual step {:.4g}, effort {}\n",
             OperatorSummary(options.operator_name, report.segment_operators), report.rank,
             report.anchors, report.segments, step, options.effort);
  PrintSegmentDetails(report, options.operator_name);
  if (report.measured) {
    fmt::print("  KG {:.4f}  STED {:.5f} (spatial {:.5f}, temporal {:.5f})  RMSE/diag {:.3g}\n",
               report.distortion.kg, report.distortion.sted, report.distortion.sted_s,
               report.distortion.sted_t, report.distortion.rmse_rel);
  }
  if (!report.not_measured_reason.empty()) {
    fmt::print("  not measured (decoded and checked): {}\n", report.not_measured_reason);
  }
  fmt::print("  bpfv by element:");
  for (const auto& [name, bytes] : breakdown.items()) {
    if (name == "scene" && report.scene_bytes == 0) continue;
    fmt::print(" {} {:.4f}", name, bytes.get<double>() * scale);
  }
  fmt::print("\n");
  if (report.scene_bytes > 0) {
    fmt::print("  scene {} bytes; positions alone {:.4f} bpfv\n", report.scene_bytes,
               report.positions_bpfv);
  }
  return 0;
}

// Every option of the table (dmc/encoder_options.h) as a flag bound to its field: --name VALUE,
// or for a switch --name and --no-name.
void AddEncoderOptions(CLI::App* app, EncoderOptions& options) {
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    const std::string flag = SpellOption(spec.name, OptionSpelling::kCliFlag);
    const std::string help(spec.help);
    std::visit(
        [&](auto field) {
          auto& value = options.*field;
          if constexpr (std::is_same_v<std::remove_reference_t<decltype(value)>, bool>) {
            app->add_flag(flag + ",!--no-" + flag.substr(2), value,
                          help + (value ? " (default: on)" : " (default: off)"));
          } else {
            app->add_option(flag, value, help)->capture_default_str();
          }
        },
        spec.field);
  }
}

// The table names of the encoder options given on `app`'s command line (either spelling of a
// switch).
std::vector<std::string> GivenEncoderOptions(const CLI::App& app) {
  std::vector<std::string> given;
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    if (app.count(SpellOption(spec.name, OptionSpelling::kCliFlag)) > 0) {
      given.emplace_back(spec.name);
    }
  }
  return given;
}

}  // namespace

Command AddEncodeCommand(CLI::App& parent) {
  auto args = std::make_shared<EncodeArgs>();
  CLI::App* app = parent.add_subcommand("encode", "Compress a mesh sequence to a .dmc stream");
  app->add_option("-i,--input,INPUT", args->input,
                  "Sequence: frame directory, glob, mesh file, .pc2 or .glb/.gltf")
      ->required();
  app->add_option("-o,--output", args->output, "Output .dmc file")->required();
  app->add_option("--connectivity", args->connectivity, "PC2 only: mesh giving the triangles");
  AddGltfReadOptions(app, &args->gltf);
  app->add_flag("--no-scene", args->no_scene,
                "glTF input: leave out the scene chunk (nodes, materials, textures, UVs, clips; "
                "decoding then writes the motion alone)");
  AddEncoderOptions(app, args->options);
  app->add_flag("--json", args->json, "Machine-readable output");
  app->add_flag("--progress", args->progress,
                "Show progress on stderr even when it is not a terminal");
  return {app, [args, app] {
            args->given = GivenEncoderOptions(*app);
            return RunEncode(*args);
          }};
}

}  // namespace dmc::cli

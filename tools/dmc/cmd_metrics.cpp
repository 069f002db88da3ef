// dmc metrics: distortion of a sequence against its original — KG, STED (and its spatial and
// temporal parts), RMSE relative to the bounding-box diagonal, maximum vertex error.
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "dmc/io.h"
#include "dmc/metrics.h"

namespace dmc::cli {
namespace {

struct MetricsArgs {
  std::string original;
  std::string distorted;
  StedOptions sted;
  GltfReadFlags gltf;  // the same options for both inputs
  bool json = false;
};

// Reads one input, printing its read warnings (on stderr) unless the output is JSON.
StatusOr<MeshSequence> ReadInput(const std::string& path, const std::string& role,
                                 const GltfReadOptions& gltf, bool json) {
  ReadOptions options;
  options.gltf = gltf;
  std::optional<Progress> progress;
  options.progress = [&progress, &role](int done, int total) {
    if (!progress) progress.emplace("reading " + role, total);
    progress->Update(done);
  };
  ReadReport report;
  StatusOr<MeshSequence> sequence = ReadSequence(path, options, &report);
  progress.reset();
  if (!json) {
    for (const std::string& warning : report.warnings) ReportWarning("metrics", warning);
  }
  return sequence;
}

int RunMetrics(const MetricsArgs& args) {
  // Options first: a typo should not cost two sequence reads.
  if (Status valid = ValidateStedOptions(args.sted); !valid.ok()) {
    return ReportError("metrics", valid, args.json);
  }
  WarnIfGltfOptionsUnused("metrics", args.gltf, {args.original, args.distorted});
  StatusOr<MeshSequence> original =
      ReadInput(args.original, "original", args.gltf.options, args.json);
  if (!original.ok()) return ReportError("metrics", original.status(), args.json);
  StatusOr<MeshSequence> distorted =
      ReadInput(args.distorted, "distorted", args.gltf.options, args.json);
  if (!distorted.ok()) return ReportError("metrics", distorted.status(), args.json);

  const StatusOr<DistortionReport> report = MeasureDistortion(*original, *distorted, args.sted);
  if (!report.ok()) return ReportError("metrics", report.status(), args.json);

  if (args.json) {
    PrintJson({
        {"kg", report->kg},
        {"sted", report->sted},
        {"sted_s", report->sted_s},
        {"sted_t", report->sted_t},
        {"rmse_rel", report->rmse_rel},
        {"max_error", report->max_error},
        {"frames", report->frames},
        {"vertices", report->vertices},
    });
    return 0;
  }
  const auto row = [](std::string_view label, double value) {
    fmt::print("  {:<26}{:.9g}\n", label, value);
  };
  fmt::print("{} against {}: {} frame(s) of {} vertices\n", args.distorted, args.original,
             report->frames, report->vertices);
  row("KG error (%)", report->kg);
  row("STED", report->sted);
  row("STED_s (spatial)", report->sted_s);
  row("STED_t (temporal)", report->sted_t);
  row("RMSE / bbox diagonal", report->rmse_rel);
  row("max vertex error", report->max_error);
  fmt::print("  (STED with w = {}, dt = {}, s = {}, c = {})\n", args.sted.width, args.sted.dt,
             args.sted.window, args.sted.c);
  return 0;
}

}  // namespace

Command AddMetricsCommand(CLI::App& parent) {
  auto args = std::make_shared<MetricsArgs>();
  CLI::App* app = parent.add_subcommand(
      "metrics",
      "Measure the distortion of DISTORTED against ORIGINAL: KG error, STED (spatial and "
      "temporal parts), RMSE relative to the bounding-box diagonal, maximum vertex error. The "
      "original defines STED's edge lengths, diameter and local speed, so the order matters");
  const std::string input_help =
      "A directory of .obj/.off/.ply frames, a glob such as 'dir/f_*.obj' (quoted), one mesh "
      "file, a .pc2 cache, or a .glb/.gltf animation";
  app->add_option("original", args->original, "The reference sequence. " + input_help)->required();
  app->add_option("distorted", args->distorted,
                  "The sequence to measure (same frames, vertices and triangles). " + input_help)
      ->required();
  AddGltfReadOptions(app, &args->gltf, "glTF inputs (the same for both)");
  app->add_flag("--json", args->json,
                "Print a JSON object with keys kg, sted, sted_s, sted_t, rmse_rel, max_error, "
                "frames, vertices");
  app->add_option("--sted-width", args->sted.width,
                  "STED neighbourhood width w in one-ring steps (>= 0)")
      ->capture_default_str();
  app->add_option("--sted-dt", args->sted.dt, "STED frame distance dt (>= 0)")
      ->capture_default_str();
  app->add_option("--sted-window", args->sted.window, "STED speed window s in frames (>= 1)")
      ->capture_default_str();
  app->add_option("--sted-c", args->sted.c, "STED weight c of the temporal part (>= 0)")
      ->capture_default_str();
  return {app, [args] { return RunMetrics(*args); }};
}

}  // namespace dmc::cli

// dmc info: what a mesh sequence holds — sizes, topology, bounds, frame rate, warnings.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "cli_util.h"
#include "commands.h"
#include "dmc/decoder.h"
#include "dmc/io.h"
#include "dmc/topology.h"

namespace dmc::cli {
namespace {

struct InfoArgs {
  std::string input;
  std::string connectivity;
  int max_frames = 0;
  GltfReadFlags gltf;
  bool json = false;
};

// A .dmc stream: container header, segments, operators, parameters and chunk sizes (parsed and
// checksum-verified without decoding).
int RunStreamInfo(const InfoArgs& args) {
  auto bytes = ReadFileBytes(args.input);
  if (!bytes.ok()) return ReportError("info", bytes.status(), args.json);
  auto info = ReadStreamInfo(*bytes);
  if (!info.ok()) return ReportError("info", info.status().WithContext(args.input), args.json);
  const double value_count = static_cast<double>(info->frame_count) * info->vertex_count;
  const auto bpfv = [&](uint64_t bytes_used) { return 8.0 * bytes_used / value_count; };
  // A scene (format 1.3) lists the input's clips; reading them decompresses it.
  std::vector<ClipInfo> clips;
  if (info->scene_bytes > 0) {
    auto scene = DecodeScene(*bytes);
    if (!scene.ok()) return ReportError("info", scene.status().WithContext(args.input), args.json);
    auto listed = SceneClips(*scene);
    if (listed.ok()) {
      clips = std::move(listed).value();
    } else {
      ReportWarning("info",
                    "the stream's scene is not a dmc scene record: " + listed.status().message());
    }
  }
  nlohmann::json clips_json = nlohmann::json::array();
  for (const ClipInfo& clip : clips) {
    clips_json.push_back({{"name", clip.name},
                          {"first_frame", clip.first_frame},
                          {"frames", clip.frame_count},
                          {"start_time", clip.start_time}});
  }
  if (args.json) {
    nlohmann::json segments = nlohmann::json::array();
    for (const SegmentInfo& s : info->segments) {
      segments.push_back({{"first_frame", s.first_frame},
                          {"frames", s.frame_count},
                          {"rank", s.rank},
                          {"operator", s.operator_name},
                          {"operator_id", s.operator_id},
                          {"basis_bits", s.basis_bits},
                          {"weight_bits", s.weight_bits},
                          {"anchors", s.anchor_count},
                          {"residual_step", s.residual_step},
                          {"anchor_step", s.anchor_step},
                          {"bytes",
                           {{"header", s.header_bytes},
                            {"mean", s.mean_bytes},
                            {"basis", s.basis_bytes},
                            {"operator", s.operator_bytes},
                            {"anchors", s.anchor_bytes},
                            {"residuals", s.residual_bytes}}}});
    }
    PrintJson({{"input", args.input},
               {"format_version", fmt::format("{}.{}", info->version_major, info->version_minor)},
               {"name", info->name},
               {"vertices", info->vertex_count},
               {"triangles", info->triangle_count},
               {"frames", info->frame_count},
               {"frame_rate", info->frame_rate > 0.0 ? nlohmann::json(info->frame_rate)
                                                     : nlohmann::json(nullptr)},
               {"reordered", info->reordered},
               {"bytes", info->total_bytes},
               {"bpfv", bpfv(info->total_bytes)},
               {"header_bytes", info->header_bytes},
               {"connectivity_bytes", info->connectivity_bytes},
               {"scene_bytes", info->scene_bytes},
               {"scene_size", info->scene_size},
               {"clips", clips_json},
               {"segments", segments}});
    return 0;
  }
  fmt::print(
      "{}: dmc stream {}.{}, {} frame(s) of {} vertices, {} triangles, {} bytes ({:.4f} bpfv)\n",
      args.input, info->version_major, info->version_minor, info->frame_count, info->vertex_count,
      info->triangle_count, info->total_bytes, bpfv(info->total_bytes));
  fmt::print("  name '{}', frame rate {}, vertex order {}\n", info->name,
             info->frame_rate > 0.0 ? fmt::format("{} fps", info->frame_rate) : "unknown",
             info->reordered ? "the codec's own" : "the input's");
  fmt::print("  header {} B, connectivity {} B ({:.4f} bpfv)\n", info->header_bytes,
             info->connectivity_bytes, bpfv(info->connectivity_bytes));
  if (info->scene_bytes > 0) {
    fmt::print("  scene {} B ({} B decompressed), {} clip(s)\n", info->scene_bytes,
               info->scene_size, clips.size());
    for (const ClipInfo& clip : clips) {
      fmt::print("    clip '{}': frames {}..{}\n", clip.name, clip.first_frame,
                 clip.first_frame + clip.frame_count - 1);
    }
  }
  for (size_t i = 0; i < info->segments.size(); ++i) {
    const SegmentInfo& s = info->segments[i];
    fmt::print(
        "  segment {}: frames {}..{}, operator {}, rank {}, {} anchors, basis {} bits, residual "
        "step {:.4g}\n    bytes: header {}, mean {}, basis {}, operator {}, anchors {}, residuals "
        "{}\n",
        i, s.first_frame, s.first_frame + s.frame_count - 1, s.operator_name, s.rank,
        s.anchor_count, s.basis_bits, s.residual_step, s.header_bytes, s.mean_bytes, s.basis_bytes,
        s.operator_bytes, s.anchor_bytes, s.residual_bytes);
  }
  return 0;
}

int RunInfo(const InfoArgs& args) {
  WarnIfGltfOptionsUnused("info", args.gltf, {args.input});
  if (std::filesystem::path(args.input).extension() == ".dmc") return RunStreamInfo(args);
  ReadOptions options;
  options.connectivity = args.connectivity;
  options.max_frames = args.max_frames;
  options.gltf = args.gltf.options;
  std::optional<Progress> progress;
  options.progress = [&progress](int done, int total) {
    if (!progress) progress.emplace("reading", total);
    progress->Update(done);
  };
  ReadReport report;
  StatusOr<MeshSequence> read = ReadSequence(args.input, options, &report);
  progress.reset();
  if (!read.ok()) return ReportError("info", read.status(), args.json);
  const MeshSequence& sequence = *read;

  const MeshTopology topology = BuildTopology(sequence.triangles(), sequence.vertex_count());
  ValidationReport validation;
  const Status valid = ValidateSequence(sequence, &validation);
  if (!valid.ok()) return ReportError("info", valid, args.json);
  const BoundingBox box = ComputeBoundingBox(sequence);

  if (args.json) {
    nlohmann::json out = {
        {"input", args.input},
        {"name", sequence.name},
        {"vertices", sequence.vertex_count()},
        {"triangles", sequence.triangle_count()},
        {"frames", sequence.frame_count()},
        {"frame_rate",
         sequence.frame_rate > 0.0 ? nlohmann::json(sequence.frame_rate) : nlohmann::json(nullptr)},
        {"edges", topology.edge_count()},
        {"boundary_edges", topology.boundary_edge_count},
        {"boundary_loops", topology.boundary_loop_count},
        {"components", topology.component_count},
        {"isolated_vertices", topology.isolated_vertex_count},
        {"non_manifold_edges", topology.non_manifold_edge_count},
        {"manifold", topology.is_manifold()},
        {"euler_characteristic", topology.euler_characteristic},
        {"degenerate_triangles", validation.degenerate_triangles},
        {"bounding_box",
         {{"min", {box.min.x(), box.min.y(), box.min.z()}},
          {"max", {box.max.x(), box.max.y(), box.max.z()}},
          {"diagonal", box.diagonal()}}},
        {"warnings", report.warnings},
    };
    if (!report.clips.empty()) {
      out["clips"] = nlohmann::json::array();
      for (const ClipInfo& clip : report.clips) {
        out["clips"].push_back(
            {{"name", clip.name}, {"first_frame", clip.first_frame}, {"frames", clip.frame_count}});
      }
    }
    PrintJson(out);
    return 0;
  }
  for (const std::string& warning : report.warnings) ReportWarning("info", warning);
  const auto row = [](std::string_view label, const std::string& value) {
    fmt::print("  {:<22}{}\n", label, value);
  };
  fmt::print("{}: {} frame(s) of {} vertices, {} triangles\n", args.input, sequence.frame_count(),
             sequence.vertex_count(), sequence.triangle_count());
  row("frame rate",
      sequence.frame_rate > 0.0 ? fmt::format("{} fps", sequence.frame_rate) : "unknown");
  row("edges", std::to_string(topology.edge_count()));
  row("boundary", fmt::format("{} edge(s) in {} loop(s)", topology.boundary_edge_count,
                              topology.boundary_loop_count));
  row("components", fmt::format("{} ({} isolated vertices)", topology.component_count,
                                topology.isolated_vertex_count));
  row("non-manifold edges", std::to_string(topology.non_manifold_edge_count));
  row("Euler characteristic", std::to_string(topology.euler_characteristic));
  row("degenerate triangles", std::to_string(validation.degenerate_triangles));
  row("bounding box",
      fmt::format("[{:.6g}, {:.6g}, {:.6g}] to [{:.6g}, {:.6g}, {:.6g}]", box.min.x(), box.min.y(),
                  box.min.z(), box.max.x(), box.max.y(), box.max.z()));
  row("diagonal", fmt::format("{:.6g}", box.diagonal()));
  for (size_t c = 0; c < report.clips.size(); ++c) {
    const ClipInfo& clip = report.clips[c];
    row(c == 0 ? "clips" : "",
        fmt::format("{}: frames {}..{}", clip.name.empty() ? "#" + std::to_string(c) : clip.name,
                    clip.first_frame, clip.first_frame + clip.frame_count - 1));
  }
  return 0;
}

}  // namespace

Command AddInfoCommand(CLI::App& parent) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* app = parent.add_subcommand(
      "info",
      "Describe a mesh sequence: vertices, triangles, frames, edges, boundary, "
      "components, manifoldness, Euler characteristic, bounding box");
  app->add_option("-i,--input,input", args->input,
                  "A directory of .obj/.off/.ply frames, a glob such as 'dir/f_*.obj' (quoted), "
                  "one mesh file, a .pc2 cache, a .glb/.gltf animation, or a .dmc stream")
      ->required();
  app->add_option("--connectivity", args->connectivity,
                  "PC2 only: mesh file giving the triangles (default: <stem>.obj, .off or .ply "
                  "beside the cache)");
  app->add_option("--max-frames", args->max_frames, "Read only the first N frames (0 = all)")
      ->check(CLI::NonNegativeNumber);
  AddGltfReadOptions(app, &args->gltf);
  app->add_flag("--json", args->json, "Print a JSON object instead of text");
  return {app, [args] { return RunInfo(*args); }};
}

}  // namespace dmc::cli

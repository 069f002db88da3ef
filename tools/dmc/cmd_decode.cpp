// dmc decode: reconstruct a mesh sequence from a .dmc stream.
#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "dmc/decoder.h"
#include "dmc/io.h"

namespace dmc::cli {
namespace {

struct DecodeArgs {
  std::string input;
  std::string output;
  std::string frame_format = "obj";
  std::string glb_layout = "auto";
  std::string glb_encoding = "compact";
  bool glb_float = false;
  bool no_scene = false;
  std::string clip;
  int segment = -1;
  bool json = false;
  bool progress = false;
  uint64_t max_memory = DecoderOptions().max_output_bytes;
};

// The library names the limit; the command line names the flag that raises it.
Status WithLimitHint(const Status& status) {
  if (status.code() != ErrorCode::kResourceLimit) return status;
  return Status(status.code(), status.message() + " (raise it with --max-memory, 0 for none)");
}

int RunDecode(const DecodeArgs& args) {
  if ((args.glb_float || args.glb_encoding != "compact") &&
      LowercaseExtension(args.output) != ".glb") {
    ReportWarning("decode", "--float and --glb-encoding ignored: the output is not a .glb");
  }
  if (const Status distinct = RefuseOutputThatIsAnInput(args.output, args.input); !distinct.ok()) {
    return ReportError("decode", distinct, args.json);
  }
  if (const Status path = CheckSequenceOutputPath(args.output); !path.ok()) {
    return ReportError("decode", path, args.json);
  }
  auto bytes = ReadFileBytes(args.input);
  if (!bytes.ok()) return ReportError("decode", bytes.status(), args.json);
  DecoderOptions options;
  options.max_output_bytes = args.max_memory;
  options.max_matrix_bytes = args.max_memory;
  std::optional<Progress> progress;
  auto show = [&](int done, int total) {
    if (!progress) progress.emplace("decoding", total, args.progress);
    progress->Update(done);
  };

  if (args.segment < 0 && IsPc2Path(args.output)) {
    // A PC2 cache is written segment by segment as they decode: the whole sequence is never in
    // memory. Two segments in flight keep both cores busy on multi-segment streams (the output
    // does not depend on it: see DecodeToPc2) for at most two decoded segments in memory.
    const Status status = DecodeToPc2(*bytes, args.output, show, 2, options);
    progress.reset();
    if (!status.ok()) {
      return ReportError("decode", WithLimitHint(status.WithContext(args.input)), args.json);
    }
    auto info = ReadStreamInfo(*bytes);
    if (!info.ok()) return ReportError("decode", info.status().WithContext(args.input), args.json);
    if (args.json) {
      PrintJson({{"output", args.output},
                 {"frames", info->frame_count},
                 {"vertices", info->vertex_count},
                 {"triangles", info->triangle_count}});
    } else {
      fmt::print("{}: {} frames x {} vertices, {} triangles\n", args.output, info->frame_count,
                 info->vertex_count, info->triangle_count);
    }
    return 0;
  }

  StatusOr<MeshSequence> sequence = InternalError("unset");
  std::vector<uint8_t> scene;  // format 1.3: the input's scene, written back into a .glb
  if (args.segment >= 0) {
    Decoder decoder;
    const Status open = decoder.Open(*bytes, options);
    if (!open.ok()) {
      return ReportError("decode", WithLimitHint(open.WithContext(args.input)), args.json);
    }
    sequence = decoder.DecodeSegment(args.segment);
    scene = decoder.scene();
  } else {
    show(0, 1);
    sequence = Decode(*bytes, options, &scene);
    if (sequence.ok()) show(1, 1);
    progress.reset();
  }
  if (!sequence.ok()) {
    return ReportError("decode", WithLimitHint(sequence.status().WithContext(args.input)),
                       args.json);
  }
  WriteOptions write_options;
  write_options.frame_format = args.frame_format;
  write_options.glb_layout = args.glb_layout;
  write_options.glb_encoding = args.glb_float ? "float" : args.glb_encoding;
  if (LowercaseExtension(args.output) == ".glb" && !args.no_scene && !scene.empty()) {
    if (args.segment >= 0) {
      // The scene's clips span the whole stream, not one segment's frames.
      ReportWarning("decode", "--segment writes the segment's motion alone, without the scene");
    } else {
      // A glTF input's scene (format 1.3) comes back around the motion.
      write_options.scene = std::move(scene);
    }
  }
  if (!args.clip.empty() && write_options.scene.empty()) {
    return ReportError("decode",
                       InvalidArgumentError("--clip needs a .glb output of a stream with a scene"),
                       args.json);
  }
  write_options.clip = args.clip;
  if (args.segment < 0) {
    // The basis layout fits each segment's low-rank motion apart.
    auto info = ReadStreamInfo(*bytes);
    if (!info.ok()) return ReportError("decode", info.status().WithContext(args.input), args.json);
    for (const SegmentInfo& segment : info->segments) {
      write_options.motion_blocks.push_back(segment.first_frame);
    }
  }
  std::optional<Progress> write_progress;
  write_options.progress = [&](int done, int total) {
    if (!write_progress) write_progress.emplace("writing", total, args.progress);
    write_progress->Update(done);
  };
  const Status written = WriteSequence(*sequence, args.output, write_options);
  write_progress.reset();
  if (!written.ok()) return ReportError("decode", written, args.json);
  if (args.json) {
    PrintJson({{"output", args.output},
               {"frames", sequence->frame_count()},
               {"vertices", sequence->vertex_count()},
               {"triangles", sequence->triangle_count()}});
  } else {
    fmt::print("{}: {} frames x {} vertices, {} triangles\n", args.output, sequence->frame_count(),
               sequence->vertex_count(), sequence->triangle_count());
  }
  return 0;
}

}  // namespace

Command AddDecodeCommand(CLI::App& parent) {
  auto args = std::make_shared<DecodeArgs>();
  CLI::App* app = parent.add_subcommand("decode", "Reconstruct a mesh sequence from a .dmc stream");
  app->add_option("-i,--input,INPUT", args->input, "Input .dmc file")->required();
  app->add_option("-o,--output", args->output,
                  "Output: a directory of frames, a .pc2 cache, a .glb, or a single mesh file")
      ->required();
  app->add_option("--frame-format", args->frame_format, "obj, off or ply for frame directories")
      ->capture_default_str();
  app->add_option("--glb-layout", args->glb_layout,
                  "auto, basis, morph or frames: how a .glb output animates the frames (basis: a "
                  "few morph targets per segment; morph: one per frame; frames: one mesh per "
                  "frame; auto: with a scene basis, else the smallest file)")
      ->capture_default_str();
  app->add_option("--glb-encoding", args->glb_encoding,
                  "compact (KHR_mesh_quantization + EXT_meshopt_compression), quantized (without "
                  "meshopt, for readers that lack its decoder, e.g. Blender) or float (float32)")
      ->check(CLI::IsMember({"compact", "quantized", "float"}))
      ->capture_default_str();
  app->add_flag("--float", args->glb_float, "Same as --glb-encoding float");
  app->add_flag("--no-scene", args->no_scene,
                "A .glb output with the motion alone, leaving out the stream's scene (nodes, "
                "materials, textures, UVs, clips)");
  app->add_option("--clip", args->clip,
                  "A .glb output of a stream with a scene: only this clip (dmc info lists them)");
  app->add_option("--segment", args->segment, "Decode only this segment (0-based)");
  app->add_option("--max-memory", args->max_memory,
                  "Refuse a stream whose decoded output (12 bytes per vertex and frame, 12 per "
                  "triangle), or a segment's normal matrix or factor, would exceed SIZE, before "
                  "building it; 0: no limit but the format's 16 GiB of output")
      ->transform(CLI::AsSizeValue(false))
      ->default_str("4GiB");
  app->add_flag("--json", args->json, "Machine-readable output");
  app->add_flag("--progress", args->progress,
                "Show progress on stderr even when it is not a terminal");
  return {app, [args] { return RunDecode(*args); }};
}

}  // namespace dmc::cli

// dmc convert: read a mesh sequence in one layout and write it in another (frames directory,
// single mesh file, PC2 cache), keeping vertex and triangle order and every float bit.
#include <fmt/format.h>

#include <memory>
#include <optional>

#include "cli_util.h"
#include "commands.h"
#include "dmc/io.h"

namespace dmc::cli {
namespace {

struct ConvertArgs {
  std::string input;
  std::string output;
  std::string frame_format = "obj";
  std::string glb_encoding = "float";
  std::string connectivity;
  int max_frames = 0;
  GltfReadFlags gltf;
  bool json = false;
};

int RunConvert(const ConvertArgs& args) {
  WarnIfGltfOptionsUnused("convert", args.gltf, {args.input});
  std::optional<Progress> progress;
  auto report_progress = [&progress](std::string label) {
    return [&progress, label](int done, int total) {
      if (!progress) progress.emplace(label, total);
      progress->Update(done);
    };
  };
  if (const Status distinct = RefuseOutputThatIsAnInput(args.output, args.input, args.connectivity);
      !distinct.ok()) {
    return ReportError("convert", distinct, args.json);
  }
  if (const Status path = CheckSequenceOutputPath(args.output); !path.ok()) {
    return ReportError("convert", path, args.json);
  }
  ReadOptions read_options;
  read_options.connectivity = args.connectivity;
  read_options.max_frames = args.max_frames;
  read_options.gltf = args.gltf.options;
  read_options.progress = report_progress("reading");
  ReadReport report;
  StatusOr<MeshSequence> sequence = ReadSequence(args.input, read_options, &report);
  progress.reset();
  if (!sequence.ok()) return ReportError("convert", sequence.status(), args.json);
  if (!args.json) {
    for (const std::string& warning : report.warnings) ReportWarning("convert", warning);
  }

  if (args.glb_encoding != "float" && LowercaseExtension(args.output) != ".glb") {
    ReportWarning("convert", "--glb-encoding ignored: the output is not a .glb");
  }
  WriteOptions write_options;
  write_options.frame_format = args.frame_format;
  // convert keeps every float bit unless asked otherwise, so its GLBs are float32 by default.
  write_options.glb_encoding = args.glb_encoding;
  write_options.progress = report_progress("writing");
  const Status written = WriteSequence(*sequence, args.output, write_options);
  progress.reset();
  if (!written.ok()) return ReportError("convert", written, args.json);

  if (args.json) {
    PrintJson({{"input", args.input},
               {"output", args.output},
               {"frames", sequence->frame_count()},
               {"vertices", sequence->vertex_count()},
               {"triangles", sequence->triangle_count()},
               {"warnings", report.warnings}});
  } else {
    fmt::print("{} -> {}: {} frame(s) of {} vertices, {} triangles\n", args.input, args.output,
               sequence->frame_count(), sequence->vertex_count(), sequence->triangle_count());
  }
  return 0;
}

}  // namespace

Command AddConvertCommand(CLI::App& parent) {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* app = parent.add_subcommand(
      "convert",
      "Convert a mesh sequence: OUTPUT ending in .pc2 writes a point cache plus <stem>.obj; "
      "ending in .obj/.off/.ply writes one mesh (1-frame input); .glb a glTF animation; a path "
      "without an extension (or ending in /) a directory of frame_NNNN files; any other "
      "extension is refused");
  app->add_option("-i,--input,input", args->input,
                  "A directory of .obj/.off/.ply frames, a glob such as 'dir/f_*.obj' (quoted), "
                  "one mesh file, a .pc2 cache, or a .glb/.gltf animation")
      ->required();
  app->add_option("-o,--output", args->output, "Output path (see above)")->required();
  app->add_option("--frame-format", args->frame_format,
                  "Frame file format when OUTPUT is a directory")
      ->check(CLI::IsMember({"obj", "off", "ply"}))
      ->capture_default_str();
  app->add_option("--connectivity", args->connectivity,
                  "PC2 input only: mesh file giving the triangles (default: <stem>.obj, .off or "
                  ".ply beside the cache)");
  app->add_option("--max-frames", args->max_frames, "Convert only the first N frames (0 = all)")
      ->check(CLI::NonNegativeNumber);
  AddGltfReadOptions(app, &args->gltf);
  app->add_option("--glb-encoding", args->glb_encoding,
                  "float (every bit kept), compact (KHR_mesh_quantization + "
                  "EXT_meshopt_compression, as dmc decode writes) or quantized (without meshopt)")
      ->check(CLI::IsMember({"compact", "quantized", "float"}))
      ->capture_default_str();
  app->add_flag("--json", args->json, "Print a JSON summary instead of text");
  return {app, [args] { return RunConvert(*args); }};
}

}  // namespace dmc::cli

// dmc synth: generate one of the built-in synthetic animations and write it like `dmc convert`
// writes (a .pc2 cache plus <stem>.obj, one mesh file, or a directory of frames).
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "dmc/io.h"
#include "dmc/synth.h"
#include "dmc/tvm.h"

namespace dmc::cli {
namespace {

struct SynthArgs {
  std::string name;
  std::string output;
  SynthOptions options;
  std::string frame_format = "obj";
  bool json = false;
  int centres = 300;  // time-varying generators only
};

// prism, collision: frames with their own connectivity in OUTPUT/, centres in OUTPUT/centres.txt.
int RunTimeVaryingSynth(const SynthArgs& args) {
  TimeVaryingSynthOptions options;
  options.frames = args.options.frames;
  options.resolution = args.options.resolution;
  options.centres = args.centres;
  options.seed = args.options.seed;
  StatusOr<TimeVaryingSynthesis> synthesis = SynthesizeTimeVarying(args.name, options);
  if (!synthesis.ok()) return ReportError("synth", synthesis.status(), args.json);
  const std::filesystem::path output = args.output;
  Status written = tvm::WriteTimeVaryingMesh(synthesis->mesh, output, args.frame_format);
  if (written.ok()) written = tvm::WriteCentres(synthesis->centres, output / tvm::kCentresFileName);
  if (!written.ok()) return ReportError("synth", written, args.json);
  int min_vertices = synthesis->mesh.frames.front().vertex_count(), max_vertices = min_vertices;
  for (const auto& frame : synthesis->mesh.frames) {
    min_vertices = std::min(min_vertices, frame.vertex_count());
    max_vertices = std::max(max_vertices, frame.vertex_count());
  }
  const std::string centres_path = (output / tvm::kCentresFileName).string();
  if (args.json) {
    PrintJson({{"name", synthesis->mesh.name},
               {"time_varying", true},
               {"frames", synthesis->mesh.frame_count()},
               {"min_vertices", min_vertices},
               {"max_vertices", max_vertices},
               {"centres", synthesis->centres.centre_count()},
               {"frame_rate", synthesis->mesh.frame_rate},
               {"seed", args.options.seed},
               {"output", args.output},
               {"centres_file", centres_path}});
  } else {
    fmt::print(
        "{}: {} frame(s) of {}-{} vertices (connectivity varies), {} centres at {:g} fps "
        "(seed {}) -> {} and {}\n",
        synthesis->mesh.name, synthesis->mesh.frame_count(), min_vertices, max_vertices,
        synthesis->centres.centre_count(), synthesis->mesh.frame_rate, args.options.seed,
        args.output, centres_path);
  }
  return 0;
}

int RunSynth(const SynthArgs& args) {
  const auto time_varying = TimeVaryingSynthNames();
  if (std::find(time_varying.begin(), time_varying.end(), args.name) != time_varying.end()) {
    return RunTimeVaryingSynth(args);
  }
  if (const Status path = CheckSequenceOutputPath(args.output); !path.ok()) {
    return ReportError("synth", path, args.json);
  }
  StatusOr<MeshSequence> sequence = Synthesize(args.name, args.options);
  if (!sequence.ok()) return ReportError("synth", sequence.status(), args.json);

  std::optional<Progress> progress;
  WriteOptions write_options;
  write_options.frame_format = args.frame_format;
  write_options.progress = [&progress](int done, int total) {
    if (!progress) progress.emplace("writing", total);
    progress->Update(done);
  };
  const Status written = WriteSequence(*sequence, args.output, write_options);
  progress.reset();
  if (!written.ok()) return ReportError("synth", written, args.json);

  if (args.json) {
    PrintJson({{"name", sequence->name},
               {"vertices", sequence->vertex_count()},
               {"triangles", sequence->triangle_count()},
               {"frames", sequence->frame_count()},
               {"frame_rate", sequence->frame_rate},
               {"seed", args.options.seed},
               {"output", args.output}});
  } else {
    fmt::print("{}: {} frame(s) of {} vertices, {} triangles at {:g} fps (seed {}) -> {}\n",
               sequence->name, sequence->frame_count(), sequence->vertex_count(),
               sequence->triangle_count(), sequence->frame_rate, args.options.seed, args.output);
  }
  return 0;
}

// "twist: closed capped tube …" lines for --help, straight from the generator table.
std::string GeneratorList() {
  std::string list;
  for (std::string_view name : SynthNames()) {
    list += fmt::format("\n  {:<7} {}", name, SynthDescription(name));
  }
  for (std::string_view name : TimeVaryingSynthNames()) {
    list += fmt::format("\n  {:<9} {}", name, TimeVaryingSynthDescription(name));
  }
  return list;
}

}  // namespace

Command AddSynthCommand(CLI::App& parent) {
  auto args = std::make_shared<SynthArgs>();
  CLI::App* app = parent.add_subcommand(
      "synth",
      "Generate a built-in synthetic animation (deterministic for a given seed; 30 fps). "
      "OUTPUT ending in .pc2 writes a point cache plus <stem>.obj; ending in .obj/.off/.ply one "
      "mesh (only with --frames 1); .glb a glTF animation; a path without an extension (or "
      "ending in /) a directory of frame_NNNN files; any other extension is refused. "
      "Generators:" +
          GeneratorList());
  app->add_option("name", args->name, "Generator name (see above)")->required();
  app->add_option("-o,--output", args->output, "Output path (see above)")->required();
  app->add_option("--frames", args->options.frames, "Number of frames")->capture_default_str();
  app->add_option("--resolution", args->options.resolution,
                  "Approximate vertex count (the mesh is sampled from integer parameters, so the "
                  "actual count is within about 10% of it from 1000 up)")
      ->capture_default_str();
  app->add_option("--seed", args->options.seed, "Seed of the motion parameters")
      ->capture_default_str();
  app->add_option("--frame-format", args->frame_format,
                  "Frame file format when OUTPUT is a directory")
      ->check(CLI::IsMember({"obj", "off", "ply"}))
      ->capture_default_str();
  app->add_option("--centres", args->centres,
                  "Approximate number of volume centres (prism, collision only; written to "
                  "OUTPUT/centres.txt)")
      ->capture_default_str();
  app->add_flag("--json", args->json, "Print a JSON summary instead of text");
  return {app, [args] { return RunSynth(*args); }};
}

}  // namespace dmc::cli

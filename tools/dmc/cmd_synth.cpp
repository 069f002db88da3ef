// dmc synth: generate one of the built-in synthetic animations and write it like `dmc convert`
// writes (a .pc2 cache plus <stem>.obj, one mesh file, or a directory of frames).
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "dmc/io.h"
#include "dmc/synth.h"

namespace dmc::cli {
namespace {

struct SynthArgs {
  std::string name;
  std::string output;
  SynthOptions options;
  std::string frame_format = "obj";
  bool json = false;
};

int RunSynth(const SynthArgs& args) {
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
  return list;
}

}  // namespace

Command AddSynthCommand(CLI::App& parent) {
  auto args = std::make_shared<SynthArgs>();
  CLI::App* app = parent.add_subcommand(
      "synth",
      "Generate a built-in synthetic animation (deterministic for a given seed; 30 fps). "
      "OUTPUT ending in .pc2 writes a point cache plus <stem>.obj; ending in .obj/.off/.ply one "
      "mesh (only with --frames 1); anything else a directory of frame_NNNN files. Generators:" +
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
  app->add_flag("--json", args->json, "Print a JSON summary instead of text");
  return {app, [args] { return RunSynth(*args); }};
}

}  // namespace dmc::cli

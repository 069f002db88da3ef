#include "dmc/synth.h"

#include <string>

#include "synth/generator_table.h"
#include "synth/generators.h"

namespace dmc {

namespace {

struct GeneratorEntry {
  std::string_view name;
  std::string_view description;
  MeshSequence (*generate)(const SynthOptions&);
};

// The generator table: one row per built-in animation, in the order SynthNames() lists them.
constexpr GeneratorEntry kGenerators[] = {
    {"twist", "closed capped tube of elliptic section that twists and bends", synth::GenerateTwist},
    {"cloth", "flag pinned on one edge, waving (travelling waves + noise); has a boundary",
     synth::GenerateCloth},
    {"walker", "six-part figure walking, linear blend skinning of an 11-bone skeleton",
     synth::GenerateWalker},
    {"blob", "sphere with slowly varying spherical-harmonic deformation", synth::GenerateBlob},
};

}  // namespace

std::vector<std::string_view> SynthNames() { return synth::GeneratorNames(kGenerators); }

std::string_view SynthDescription(std::string_view name) {
  return synth::GeneratorDescription(kGenerators, name);
}

StatusOr<MeshSequence> Synthesize(std::string_view name, const SynthOptions& options) {
  const GeneratorEntry* entry = synth::FindGenerator(kGenerators, name);
  if (entry == nullptr) {
    return NotFoundError("unknown synthetic sequence '" + std::string(name) +
                         "'; known: " + synth::JoinedGeneratorNames(kGenerators));
  }
  if (options.frames < 1 || options.frames > kMaxSynthFrames) {
    return InvalidArgumentError("frames must be in [1, " + std::to_string(kMaxSynthFrames) +
                                "], got " + std::to_string(options.frames));
  }
  if (options.resolution < kMinSynthResolution || options.resolution > kMaxSynthResolution) {
    return InvalidArgumentError("resolution must be in [" + std::to_string(kMinSynthResolution) +
                                ", " + std::to_string(kMaxSynthResolution) + "] vertices, got " +
                                std::to_string(options.resolution));
  }
  return entry->generate(options);
}

}  // namespace dmc

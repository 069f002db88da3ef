// The generator functions behind the Synthesize() table, one per file. Options are already
// validated by Synthesize(); each returns a complete sequence named after the generator.
#pragma once

#include "dmc/sequence.h"
#include "dmc/synth.h"

namespace dmc::synth {

MeshSequence GenerateTwist(const SynthOptions& options);
MeshSequence GenerateCloth(const SynthOptions& options);
MeshSequence GenerateWalker(const SynthOptions& options);
MeshSequence GenerateBlob(const SynthOptions& options);

}  // namespace dmc::synth

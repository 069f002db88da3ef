// Embedding dmc: make an animation, compress it, decompress it, measure the distortion.
#include <dmc/decoder.h>
#include <dmc/encoder.h>
#include <dmc/metrics.h>
#include <dmc/synth.h>

#include <cstdio>

int main() {
  auto sequence = dmc::Synthesize("blob", {.frames = 40, .resolution = 2000});
  if (!sequence.ok()) return std::fprintf(stderr, "%s\n", sequence.status().ToString().c_str()), 1;
  dmc::EncoderOptions options;  // DDL operator, automatic rank and anchors
  dmc::EncodeReport report;
  auto stream = dmc::Encode(*sequence, options, &report);
  if (!stream.ok()) return std::fprintf(stderr, "%s\n", stream.status().ToString().c_str()), 1;
  auto decoded = dmc::Decode(*stream);
  if (!decoded.ok()) return std::fprintf(stderr, "%s\n", decoded.status().ToString().c_str()), 1;
  auto distortion = dmc::MeasureDistortion(*sequence, *decoded);
  if (!distortion.ok()) return 1;
  std::printf("%zu bytes, %.3f bpfv, KG %.4f, STED %.5f\n", stream->size(), report.bpfv,
              distortion->kg, distortion->sted);
  return 0;
}

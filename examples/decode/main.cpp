// The smallest program that plays a .dmc stream: it links the decoder alone (dmc::decoder, or
// pkg-config's dmc-decoder), decodes the file and prints its size and one vertex per frame.
#include <dmc/decoder.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) return std::fprintf(stderr, "usage: %s STREAM.dmc\n", argv[0]), 2;
  const auto sequence = dmc::DecodeFile(argv[1]);
  if (!sequence.ok()) return std::fprintf(stderr, "%s\n", sequence.status().ToString().c_str()), 1;
  std::printf("%d vertices, %d triangles, %d frames\n", sequence->vertex_count(),
              sequence->triangle_count(), sequence->frame_count());
  for (int f = 0; f < sequence->frame_count(); ++f) {
    const auto frame = sequence->frame(f);
    std::printf("frame %d: vertex 0 at (%g, %g, %g)\n", f, frame(0, 0), frame(0, 1), frame(0, 2));
  }
  return 0;
}

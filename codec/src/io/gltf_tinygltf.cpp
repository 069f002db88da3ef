// The one translation unit that compiles tinygltf's implementation (Debian ships it header-only
// with TINYGLTF_IMPLEMENTATION; see /usr/share/doc/libtinygltf-dev/README.Debian). Image decoding
// is compiled out by gltf_format.h's macros, so stb is not needed.
#define TINYGLTF_IMPLEMENTATION
#include "io/gltf_format.h"

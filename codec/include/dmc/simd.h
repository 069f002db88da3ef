// SIMD variants of frame synthesis, the decoder's inner loop (and the encoder's, when it decodes
// to measure): Σ_k C·basis for every vertex and frame, compiled once per instruction set with
// Google Highway and chosen at run time.
//
// Every variant gives the same bits: one multiply and one add per term (no fused multiply-add),
// summed in the same order, each vector lane its own trajectory entry. The choice changes speed
// only, so forcing a variant is safe in production and is how the slower ones are measured on a
// CPU that has a faster one.
//
// Variant names: "avx512" (AVX-512 F/VL/DQ/BW), "avx2" (AVX2 + FMA + BMI2; the FMA is not used),
// "sse4", "ssse3" (x86-64), "neon" (Arm), "wasm" (WebAssembly SIMD128), "baseline" (portable
// C++, any CPU).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "dmc/status.h"

namespace dmc {

// The variants this build has and this CPU runs, fastest first; "baseline" is always last.
std::vector<std::string> SupportedSimdVariants();

// The variant synthesis runs now.
std::string ActiveSimdVariant();

// Makes every later synthesis in the process run `name`; "auto" returns to the fastest supported.
// InvalidArgument names the known variants when `name` is none of them; Unsupported when this CPU
// or build lacks it. Safe to call from any thread; a synthesis already running keeps its variant.
Status SetSimdVariant(std::string_view name);

// SetSimdVariant(value of DMC_SIMD) when that environment variable is set and not empty, else Ok.
// The dmc command line, the Python module and the benchmarks call it at start; a program
// embedding the library decides for itself whether to.
Status SetSimdVariantFromEnvironment();

}  // namespace dmc

// SIMD variants of frame synthesis, the decoder's inner loop (and the encoder's, when it decodes
// to measure): Σ_k C·basis for every vertex and frame, compiled once per instruction set with
// Google Highway and chosen at run time.
//
// Every variant gives the same bits: one multiply and one add per term (no fused multiply-add),
// summed in the same order, each vector lane its own trajectory entry. The choice changes speed
// only, so forcing a variant is safe in production and is how the slower ones are measured on a
// CPU that has a faster one.
//
// Variant names, with what Highway requires of the CPU for each: "avx512" (AVX-512 F, VL, DQ,
// BW), "avx2" (AVX2 with FMA, BMI2 and F16C; the FMA is not used), "sse4" (SSE4.2 with PCLMUL and
// AES), "ssse3" (x86-64); "neon" (64-bit Arm); "baseline" (portable C++, any CPU; WebAssembly and
// 32-bit Arm builds have only this one).
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
// or build lacks it. Safe to call from any thread; a synthesis already running may finish in
// either variant (the bits are the same).
Status SetSimdVariant(std::string_view name);

// SetSimdVariant(value of DMC_SIMD) when that environment variable is set and not empty, else Ok;
// an error names DMC_SIMD. The dmc command line and the benchmarks call it at start (and exit
// with the error), the Python module at import (which then fails with it); a program embedding
// the library decides for itself whether to.
Status SetSimdVariantFromEnvironment();

}  // namespace dmc

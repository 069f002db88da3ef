// dmc_bench's entry point: Google Benchmark's, plus the SIMD variant. DMC_SIMD (dmc/simd.h) forces
// one for every benchmark that does not force its own (the .../simd:<variant> instances do), and
// the report's context names the variant that was active and those the CPU runs.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "dmc/simd.h"

int main(int argc, char** argv) {
  const dmc::Status simd = dmc::SetSimdVariantFromEnvironment();
  if (!simd.ok()) {
    std::fprintf(stderr, "dmc_bench: %s\n", simd.ToString().c_str());
    return 1;
  }
  std::string supported;
  for (const std::string& variant : dmc::SupportedSimdVariants()) {
    supported += (supported.empty() ? "" : ",") + variant;
  }
  benchmark::AddCustomContext("dmc_simd_variant", dmc::ActiveSimdVariant());
  benchmark::AddCustomContext("dmc_simd_supported", supported);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

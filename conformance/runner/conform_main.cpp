// dmc_conform: checks the dmc decoder against conformance vectors.
//
//   dmc_conform [--bit-exact] [--quiet] PATH...
//
// PATH is a manifest (*.json) or a directory searched recursively for manifests. A valid vector
// must decode with the manifest's counts, syntax digests and positions within the spec's
// tolerance (--bit-exact: identical float bytes too); an invalid vector must fail with exactly
// the manifest's error code. Exit status: 0 all passed, 1 a vector failed, 2 usage error.
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "kit/vector_kit.h"

int main(int argc, char** argv) {
  dmc::conformance::CheckOptions options;
  bool quiet = false;
  std::vector<std::filesystem::path> manifests;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--bit-exact") {
      options.require_bit_exact = true;
    } else if (argument == "--quiet") {
      quiet = true;
    } else if (argument == "--help" || argument == "-h") {
      std::printf("usage: dmc_conform [--bit-exact] [--quiet] PATH...\n");
      return 0;
    } else if (!argument.empty() && argument[0] == '-') {
      std::fprintf(stderr, "dmc_conform: unknown option %s\n", argument.c_str());
      return 2;
    } else if (std::filesystem::is_directory(argument)) {
      for (const auto& path : dmc::conformance::FindManifests(argument)) manifests.push_back(path);
    } else if (std::filesystem::is_regular_file(argument)) {
      manifests.emplace_back(argument);
    } else {
      std::fprintf(stderr, "dmc_conform: %s does not exist\n", argument.c_str());
      return 2;
    }
  }
  if (manifests.empty()) {
    std::fprintf(stderr, "dmc_conform: no vector manifests (*.json) given\n");
    return 2;
  }
  int failed = 0;
  for (const auto& manifest : manifests) {
    const dmc::conformance::VectorResult result = dmc::conformance::CheckVector(manifest, options);
    if (!result.passed) ++failed;
    if (!result.passed || !quiet) {
      std::printf("%s %s: %s\n", result.passed ? "PASS" : "FAIL",
                  manifest.parent_path().filename().string() == "invalid"
                      ? ("invalid/" + result.name).c_str()
                      : result.name.c_str(),
                  result.detail.c_str());
    }
  }
  std::printf("%zu vector(s), %d failed\n", manifests.size(), failed);
  return failed == 0 ? 0 : 1;
}

// dmc: the command line front end of the dynamic mesh codec.
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "commands.h"
#include "dmc/simd.h"

int main(int argc, char** argv) {
  // Buffers of 1 MiB and more are mapped and go back to the system when freed. glibc's default
  // raises that threshold to the largest buffer freed so far (up to 32 MiB), after which such
  // buffers come from the heap and stay resident: the encoder's trajectories then inflated its
  // peak RSS (10k x 175 walker: 93 -> 81 MB with the fixed threshold, same time).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  // DMC_SIMD forces a SIMD variant of frame synthesis (dmc/simd.h): the output is the same, the
  // speed is that variant's. --version reports the one in use.
  if (const dmc::Status simd = dmc::SetSimdVariantFromEnvironment(); !simd.ok()) {
    std::fprintf(stderr, "error: %s\n", simd.ToString().c_str());
    return dmc::ExitCodeFor(simd.code());
  }
  CLI::App app{"dmc: compress, decode, measure and process dynamic meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", [] {
    std::string supported;
    for (const std::string& variant : dmc::SupportedSimdVariants()) {
      supported += (supported.empty() ? "" : ", ") + variant;
    }
    return "dmc 0.1.0 (SIMD variant " + dmc::ActiveSimdVariant() + "; this CPU runs " + supported +
           ")";
  });

  using AddCommand = dmc::cli::Command (*)(CLI::App&);
  // The subcommand table, in the order --help lists them.
  const AddCommand table[] = {
      dmc::cli::AddEncodeCommand,    dmc::cli::AddDecodeCommand,  dmc::cli::AddInfoCommand,
      dmc::cli::AddMetricsCommand,   dmc::cli::AddConvertCommand, dmc::cli::AddSynthCommand,
      dmc::cli::AddLaplacianCommand, dmc::cli::AddSweepCommand,   dmc::cli::AddViewCommand,
      dmc::cli::AddEditCommand,
  };
  std::vector<dmc::cli::Command> commands;
  for (AddCommand add : table) commands.push_back(add(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    // --help and --version exit 0; every usage error exits 1, the code status.h reserves for it
    // (errors of the codec itself exit 10 + their ErrorCode).
    return app.exit(error) == 0 ? 0 : 1;
  }
  for (const auto& command : commands) {
    if (command.app->parsed()) return command.run();
  }
  return 1;
}

// dmc: the command line front end of the dynamic mesh codec.
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "dmc/io.h"
#include "dmc/simd.h"
#include "dmc/version.h"

namespace {

// "encode", "edit tvm": the subcommand path that was given.
std::string CommandName(const CLI::App& app) {
  std::string name = app.get_name();
  for (const CLI::App* sub = &app; !sub->get_subcommands().empty();) {
    sub = sub->get_subcommands().front();
    name += " " + sub->get_name();
  }
  return name;
}

// Whether the deepest subcommand given had --json, so its error is reported as JSON too.
bool JsonRequested(const CLI::App& app) {
  const CLI::App* deepest = &app;
  while (!deepest->get_subcommands().empty()) deepest = deepest->get_subcommands().front();
  const CLI::Option* json = deepest->get_option_no_throw("--json");
  return json != nullptr && json->count() > 0;
}

// The last line of defence: the codec reports errors as Status and never throws, but an
// allocation can still fail (std::bad_alloc out of a container) and a dependency can throw.
// Neither may abort the process: the error is reported with its code and the temporaries of the
// write in progress, unwound by then, are removed.
int RunCommand(const dmc::cli::Command& command) {
  std::string name = "?";
  bool json = false;
  try {
    name = CommandName(*command.app);
    json = JsonRequested(*command.app);
    return command.run();
  } catch (const std::bad_alloc&) {
    dmc::RemoveTemporaryFiles();
    return dmc::cli::ReportError(
        name,
        dmc::ResourceLimitError("out of memory while running 'dmc " + name +
                                "' (an allocation failed; the input needs more memory than "
                                "the system grants)"),
        json);
  } catch (const std::exception& error) {
    dmc::RemoveTemporaryFiles();
    return dmc::cli::ReportError(
        name, dmc::InternalError(std::string("unexpected exception: ") + error.what()), json);
  } catch (...) {
    dmc::RemoveTemporaryFiles();
    return dmc::cli::ReportError(name, dmc::InternalError("unexpected exception"), json);
  }
}

// An exception that cannot be caught above (thrown through a noexcept function or out of a
// worker thread) ends in std::terminate: remove the temporaries before aborting.
[[noreturn]] void TerminateAfterCleanup() {
  dmc::RemoveTemporaryFiles();
  std::fputs("dmc: error: internal: unhandled exception, aborting\n", stderr);
  std::abort();
}

}  // namespace

int main(int argc, char** argv) try {
  // Buffers of 1 MiB and more are mapped and go back to the system when freed. glibc's default
  // raises that threshold to the largest buffer freed so far (up to 32 MiB), after which such
  // buffers come from the heap and stay resident: the encoder's trajectories then inflated its
  // peak RSS (10k x 175 walker: 93 -> 81 MB with the fixed threshold, same time).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  // Ctrl-C, kill or a closed terminal remove the hidden temporary of the output being written,
  // then end the process by the signal as before.
  if (const dmc::Status cleanup = dmc::InstallTemporaryFileCleanupOnSignals(); !cleanup.ok()) {
    std::fprintf(stderr, "error: %s\n", cleanup.ToString().c_str());
    return dmc::ExitCodeFor(cleanup.code());
  }
  std::set_terminate(TerminateAfterCleanup);
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
    return std::string("dmc ") + dmc::LibraryVersionString() + " (SIMD variant " +
           dmc::ActiveSimdVariant() + "; this CPU runs " + supported + ")";
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
    if (app.exit(error) == 0) return 0;
    for (const std::string& line : dmc::cli::SuggestCorrections(app, argc, argv)) {
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    return 1;
  }
  for (const auto& command : commands) {
    if (command.app->parsed()) return RunCommand(command);
  }
  return 1;
} catch (const std::bad_alloc&) {
  // Before or outside a command (parsing the command line, building the command table).
  std::fputs("dmc: error: resource-limit: out of memory\n", stderr);
  return dmc::ExitCodeFor(dmc::ErrorCode::kResourceLimit);
} catch (const std::exception& error) {
  std::fprintf(stderr, "dmc: error: internal: unexpected exception: %s\n", error.what());
  return dmc::ExitCodeFor(dmc::ErrorCode::kInternal);
}

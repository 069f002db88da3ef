// Placeholder until its issue lands; replaced by the real subcommand.
#include "cli_util.h"
#include "commands.h"

namespace dmc::cli {

Command AddSynthCommand(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand("synth", "(not built yet)");
  return {app, [] { return ReportError("synth", UnsupportedError("not built yet")); }};
}

}  // namespace dmc::cli

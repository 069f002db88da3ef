// Placeholder until its issue lands; replaced by the real subcommand.
#include "cli_util.h"
#include "commands.h"

namespace dmc::cli {

Command AddInfoCommand(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand("info", "(not built yet)");
  return {app, [] { return ReportError("info", UnsupportedError("not built yet")); }};
}

}  // namespace dmc::cli

// Placeholder until its issue lands; replaced by the real subcommand.
#include "cli_util.h"
#include "commands.h"

namespace dmc::cli {

Command AddMetricsCommand(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand("metrics", "(not built yet)");
  return {app, [] { return ReportError("metrics", UnsupportedError("not built yet")); }};
}

}  // namespace dmc::cli

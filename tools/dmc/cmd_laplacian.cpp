// Placeholder until its issue lands; replaced by the real subcommand.
#include "cli_util.h"
#include "commands.h"

namespace dmc::cli {

Command AddLaplacianCommand(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand("laplacian", "(not built yet)");
  return {app, [] { return ReportError("laplacian", UnsupportedError("not built yet")); }};
}

}  // namespace dmc::cli

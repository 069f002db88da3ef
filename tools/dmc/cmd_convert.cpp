// Placeholder until its issue lands; replaced by the real subcommand.
#include "cli_util.h"
#include "commands.h"

namespace dmc::cli {

Command AddConvertCommand(CLI::App& parent) {
  CLI::App* app = parent.add_subcommand("convert", "(not built yet)");
  return {app, [] { return ReportError("convert", UnsupportedError("not built yet")); }};
}

}  // namespace dmc::cli

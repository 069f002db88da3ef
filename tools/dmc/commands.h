// The dmc subcommands. Each lives in its own cmd_<name>.cpp and is listed once in main.cpp's
// table; adding a subcommand is one file plus one table row.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace dmc::cli {

// A registered subcommand: its CLI11 node and what to run when it was given. `run` returns the
// process exit code (0, or ExitCodeFor(status.code()) after printing the error).
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command AddInfoCommand(CLI::App& parent);
Command AddConvertCommand(CLI::App& parent);
Command AddSynthCommand(CLI::App& parent);
Command AddMetricsCommand(CLI::App& parent);
Command AddLaplacianCommand(CLI::App& parent);
Command AddEncodeCommand(CLI::App& parent);
Command AddDecodeCommand(CLI::App& parent);
Command AddSweepCommand(CLI::App& parent);
Command AddEditCommand(CLI::App& parent);
// A hand-written `dmc edit tvm` subcommand (cmd_edit_tvm.cpp), added to `edit` by cmd_edit.cpp.
Command AddEditTvmSubcommand(CLI::App& edit);
Command AddViewCommand(CLI::App& parent);

}  // namespace dmc::cli

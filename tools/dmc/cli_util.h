// Shared helpers of the dmc subcommands: error reporting, JSON output, progress.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>

#include "dmc/status.h"

namespace dmc::cli {

// Prints `dmc <command>: error: <code-name>: <message>` to stderr (or, with json, a JSON object
// {"error": {"code": ..., "name": ..., "message": ...}} to stdout) and returns the exit code.
int ReportError(std::string_view command, const Status& status, bool json = false);

// Prints warnings to stderr as `dmc <command>: warning: <text>`.
void ReportWarning(std::string_view command, std::string_view text);

// Pretty-prints a JSON document on stdout.
void PrintJson(const nlohmann::json& document);

// Progress on stderr ("\r<label>  42%", a newline when destroyed), only when stderr is a terminal
// or when forced (a --progress flag); silent otherwise so logs stay clean.
class Progress {
 public:
  Progress(std::string label, long total);
  Progress(std::string label, long total, bool force) : Progress(std::move(label), total) {
    enabled_ = enabled_ || force;
  }
  void Update(long done);
  ~Progress();

 private:
  std::string label_;
  long total_;
  bool enabled_;
  int last_percent_ = -1;
};

}  // namespace dmc::cli

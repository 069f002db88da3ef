// Shared helpers of the dmc subcommands: error reporting, JSON output, progress, and the glTF
// read options every sequence-reading subcommand offers.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dmc/io.h"
#include "dmc/status.h"

namespace dmc::cli {

// Prints `dmc <command>: error: <code-name>: <message>` to stderr (or, with json, a JSON object
// {"error": {"code": ..., "name": ..., "message": ...}} to stdout) and returns the exit code.
int ReportError(std::string_view command, const Status& status, bool json = false);

// For a command line that CLI11 refused: "did you mean ...?" lines for each word that is not a
// subcommand (argv[1]) or not an option of the chosen subcommand but lies within a small edit
// distance (transpositions count 1) of one that is. Empty when there is nothing to suggest.
std::vector<std::string> SuggestCorrections(const CLI::App& app, int argc, const char* const* argv);

// Prints warnings to stderr as `dmc <command>: warning: <text>`.
void ReportWarning(std::string_view command, std::string_view text);

// `document` as indented JSON text. Strings that are not UTF-8 (a stream's name is bytes, a file
// name or an OBJ line can hold any byte) have their invalid bytes replaced by U+FFFD instead of
// nlohmann's type_error aborting the command.
std::string JsonText(const nlohmann::json& document);

// kInvalidArgument when a file the command would write is a file it reads: `output` (and, for a
// .pc2 output, the .obj connectivity written beside it) against `input` (and, for a .pc2 input,
// `connectivity` or the mesh FindPc2Connectivity finds beside it) and `other_inputs` (a
// selection, a centres file; empty entries skipped), compared as files
// (std::filesystem::equivalent), so a link or another spelling of the path is caught too. An
// output that is an existing directory must not hold any of them either (it is replaced or
// written into); a glob input ("dir/*.obj") counts as its directory. Checked before any
// reading, so nothing is lost.
Status RefuseOutputThatIsAnInput(const std::string& output, const std::string& input,
                                 const std::string& connectivity = "",
                                 const std::vector<std::string>& other_inputs = {});

// Pretty-prints a JSON document on stdout (JsonText).
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

// The glTF read options of one subcommand: the values (GltfReadOptions, for ReadOptions::gltf)
// and the CLI11 options that set them, so the command can tell whether the user gave any.
struct GltfReadFlags {
  GltfReadOptions options;
  std::vector<const CLI::Option*> cli_options;  // filled by AddGltfReadOptions
};

// Adds --gltf-fps (> 0), --gltf-mesh NAME, --gltf-animation NAME|INDEX and --gltf-weld to `app`,
// writing into flags->options. Every sequence-reading subcommand uses this one definition, so the
// names, checks and help texts cannot drift apart. `applies_to` starts each help text and names
// the inputs concerned, e.g. "glTF input" or "glTF originals". `flags` must outlive parsing and
// the run (keep it in the command's shared argument struct).
void AddGltfReadOptions(CLI::App* app, GltfReadFlags* flags,
                        std::string_view applies_to = "glTF input");

// True when `path` names a .glb or .gltf file (extension compared case-insensitively), the
// only inputs ReadSequence applies GltfReadOptions to.
bool IsGltfPath(const std::filesystem::path& path);

// True when `path` names a .pc2 point cache (case-insensitively).
bool IsPc2Path(const std::filesystem::path& path);

// The --gltf-* options given explicitly on the command line, in declaration order.
std::vector<std::string> GivenGltfOptions(const GltfReadFlags& flags);

// When --gltf-* options were given but none of `inputs` is a glTF file, warns (ReportWarning)
// "--gltf-fps, --gltf-weld ignored: no .glb/.gltf input (a.obj, b.pc2)"; returns whether it
// warned. Empty entries of
// `inputs` (optional inputs not given) are skipped. A warning rather than a usage error because
// the options are harmless there, and scripts may pass one option set to mixed inputs.
bool WarnIfGltfOptionsUnused(std::string_view command, const GltfReadFlags& flags,
                             const std::vector<std::string>& inputs);

}  // namespace dmc::cli

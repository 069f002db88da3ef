#include "cli_util.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

namespace dmc::cli {

namespace {

// Optimal string alignment distance: insertions, deletions, substitutions and transpositions of
// neighbours each cost 1 ("--rnak" is 1 from "--rank").
size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

// The candidate nearest to `word`, if it is near enough to be a typo of it (at most 2 edits, and
// fewer than a third of the word's length rounded up).
std::optional<std::string> Nearest(std::string_view word, const std::vector<std::string>& names) {
  std::optional<std::string> best;
  size_t best_distance = std::min<size_t>(2, (word.size() + 2) / 3);
  for (const std::string& name : names) {
    const size_t distance = EditDistance(word, name);
    if (distance <= best_distance && (!best || distance < best_distance)) {
      best = name;
      best_distance = distance;
    }
  }
  return best;
}

}  // namespace

std::vector<std::string> SuggestCorrections(const CLI::App& app, int argc,
                                            const char* const* argv) {
  std::vector<std::string> suggestions;
  if (argc < 2) return suggestions;
  const std::string command = argv[1];
  const CLI::App* chosen = nullptr;
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands({})) {
    commands.push_back(sub->get_name());
    if (sub->get_name() == command) chosen = sub;
  }
  if (!chosen) {
    if (command.starts_with("-")) return suggestions;
    if (const auto nearest = Nearest(command, commands)) {
      suggestions.push_back("'" + command + "' is not a dmc command; did you mean '" + *nearest +
                            "'?");
    }
    return suggestions;
  }
  std::vector<std::string> flags;
  for (const CLI::Option* option : chosen->get_options()) {
    for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
    for (const std::string& name : option->get_fnames()) flags.push_back("--" + name);
  }
  for (int i = 2; i < argc; ++i) {
    std::string word = argv[i];
    if (!word.starts_with("--")) continue;
    word = word.substr(0, word.find('='));
    if (std::find(flags.begin(), flags.end(), word) != flags.end()) continue;
    if (const auto nearest = Nearest(word, flags)) {
      suggestions.push_back("dmc " + command + " has no option " + word + "; did you mean " +
                            *nearest + "?");
    }
  }
  return suggestions;
}

int ReportError(std::string_view command, const Status& status, bool json) {
  if (json) {
    nlohmann::json error = {{"error",
                             {{"code", static_cast<int>(status.code())},
                              {"name", std::string(ErrorCodeName(status.code()))},
                              {"message", status.message()}}}};
    std::cout << JsonText(error) << std::endl;
  }
  std::cerr << "dmc " << command << ": error: " << status.ToString() << std::endl;
  return ExitCodeFor(status.code());
}

void ReportWarning(std::string_view command, std::string_view text) {
  std::cerr << "dmc " << command << ": warning: " << text << std::endl;
}

std::string JsonText(const nlohmann::json& document) {
  return document.dump(2, ' ', /*ensure_ascii=*/false, nlohmann::json::error_handler_t::replace);
}

void PrintJson(const nlohmann::json& document) { std::cout << JsonText(document) << std::endl; }

namespace {

// Whether `inner` is `outer` or lies below it, both canonical.
bool IsWithin(const std::filesystem::path& inner, const std::filesystem::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

// An input as it exists on disk: the path, or for a glob pattern ("dir/mesh_*.obj"), which names
// no file itself, the directory it matches in. Empty when neither exists.
std::filesystem::path ExistingInput(const std::string& input) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (input.empty()) return {};
  const fs::path path(input);
  if (fs::exists(path, error)) return path;
  if (path.filename().string().find_first_of("*?[") != std::string::npos &&
      fs::is_directory(path.parent_path().empty() ? fs::path(".") : path.parent_path(), error)) {
    return path.parent_path().empty() ? fs::path(".") : path.parent_path();
  }
  return {};
}

}  // namespace

Status RefuseOutputThatIsAnInput(const std::string& output, const std::string& input,
                                 const std::string& connectivity,
                                 const std::vector<std::string>& other_inputs) {
  namespace fs = std::filesystem;
  // A .pc2 output is written with <stem>.obj beside it (WriteSequence); a .pc2 input reads the
  // connectivity named, or the one FindPc2Connectivity finds.
  const std::string written_mesh =
      IsPc2Path(output) ? fs::path(output).replace_extension(".obj").string() : std::string();
  std::string read_mesh = connectivity;
  if (read_mesh.empty() && IsPc2Path(input)) {
    if (const StatusOr<fs::path> found = FindPc2Connectivity(input); found.ok()) {
      read_mesh = found->string();
    }
  }
  std::vector<fs::path> read;
  for (const std::string& in : {input, read_mesh}) read.push_back(ExistingInput(in));
  for (const std::string& in : other_inputs) read.push_back(ExistingInput(in));
  const auto refuse = [](const std::string& out, const fs::path& in, const char* relation) {
    return InvalidArgumentError("output " + out + relation + in.string() +
                                ": writing it would replace what is being read; choose "
                                "another output path");
  };
  for (const std::string& out : {output, written_mesh}) {
    if (out.empty()) continue;
    std::error_code error;
    for (const fs::path& in : read) {
      if (!in.empty() && fs::equivalent(out, in, error)) return refuse(out, in, " is the input ");
    }
    // A directory output is replaced as a whole (WriteSequence) or written into (edit tvm): no
    // input may lie inside it either.
    if (!fs::is_directory(out, error)) continue;
    const fs::path directory = fs::canonical(out, error);
    if (error) continue;
    for (const fs::path& in : read) {
      if (in.empty()) continue;
      const fs::path file = fs::canonical(in, error);
      if (!error && IsWithin(file, directory)) return refuse(out, in, " holds the input ");
    }
  }
  return Status::Ok();
}

namespace {

// A positive, finite frame rate. CLI::PositiveNumber would do, but its message prints the whole
// double range ("Value 0 not in range 0.000000 to 17976931348623157...").
CLI::Validator PositiveFrameRate() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        const bool whole_text = end != text.c_str() && *end == '\0';
        if (whole_text && std::isfinite(value) && value > 0.0) return {};
        return "must be a positive number of frames per second, got '" + text + "'";
      },
      "FPS > 0");
}

}  // namespace

void AddGltfReadOptions(CLI::App* app, GltfReadFlags* flags, std::string_view applies_to) {
  const std::string prefix(applies_to);
  GltfReadOptions& options = flags->options;
  flags->cli_options = {
      app->add_option("--gltf-fps", options.frame_rate,
                      prefix + ": sampling frame rate (default: the rate a dmc export recorded, "
                               "else the key rate when the keys are uniform, else 30)")
          ->check(PositiveFrameRate()),
      app->add_option("--gltf-mesh", options.mesh,
                      prefix + ": only this mesh or node (all its primitives; default: every "
                               "mesh of the scene)"),
      app->add_option(
          "--gltf-animation", options.animation,
          prefix + ": animation name or index, or all (default: all, one after the other)"),
      app->add_flag("--gltf-weld", options.weld,
                    prefix + ": weld seam-split vertices (same position, different UV/normal)"),
  };
}

bool IsGltfPath(const std::filesystem::path& path) {
  const std::string extension = LowercaseExtension(path);
  return extension == ".glb" || extension == ".gltf";
}

bool IsPc2Path(const std::filesystem::path& path) { return LowercaseExtension(path) == ".pc2"; }

std::vector<std::string> GivenGltfOptions(const GltfReadFlags& flags) {
  std::vector<std::string> given;
  for (const CLI::Option* option : flags.cli_options) {
    if (option->count() > 0) given.push_back(option->get_name());
  }
  return given;
}

bool WarnIfGltfOptionsUnused(std::string_view command, const GltfReadFlags& flags,
                             const std::vector<std::string>& inputs) {
  const std::vector<std::string> given = GivenGltfOptions(flags);
  if (given.empty()) return false;
  std::string named_inputs;
  for (const std::string& input : inputs) {
    if (input.empty()) continue;
    if (IsGltfPath(input)) return false;
    named_inputs += (named_inputs.empty() ? "" : ", ") + input;
  }
  std::string names;
  for (const std::string& name : given) names += (names.empty() ? "" : ", ") + name;
  ReportWarning(command, names + " ignored: no .glb/.gltf input" +
                             (named_inputs.empty() ? std::string() : " (" + named_inputs + ")"));
  return true;
}

Progress::Progress(std::string label, long total)
    : label_(std::move(label)), total_(total), enabled_(isatty(STDERR_FILENO) != 0) {}

void Progress::Update(long done) {
  if (!enabled_ || total_ <= 0) return;
  const int percent = static_cast<int>(100 * done / total_);
  if (percent == last_percent_) return;
  last_percent_ = percent;
  std::fprintf(stderr, "\r%s %3d%%", label_.c_str(), percent);
  std::fflush(stderr);
}

Progress::~Progress() {
  if (enabled_ && last_percent_ >= 0) std::fprintf(stderr, "\n");
}

}  // namespace dmc::cli

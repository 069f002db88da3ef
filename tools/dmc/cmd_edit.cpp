// dmc edit: runs a Laplacian processing method from the registry (dmc/processing.h) on a mesh or
// on every frame of a sequence with one operator, and writes the result.
//
//   dmc edit METHOD INPUT -o OUTPUT --operator NAME [--selection FILE] [method options]
//
// Every registered method becomes a sub-subcommand whose options are generated from the
// parameters it declares, so adding a method to the registry adds it here with no CLI code.
// Methods that do not fit the registry's shape (different inputs, varying connectivity) are
// hand-written subcommands listed in ExtraEditSubcommands() below.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_util.h"
#include "commands.h"
#include "dmc/io.h"
#include "dmc/processing.h"

namespace dmc::cli {
namespace {

// Options every registered method shares.
struct EditArgs {
  std::string input;
  std::string output;
  std::string operator_name = "cotan";
  std::string selection;
  int operator_frame = -1;
  double ddl_mu = 0.0;
  std::string ddl_reference = "tutte";
  double max_cotangent = GeometricOptions().max_cotangent;
  std::string frame_format = "ply";
  GltfReadFlags gltf;
  bool json = false;
  // One slot per declared parameter: its CLI option and the text the user gave.
  struct ParameterSlot {
    const ParameterSpec* spec = nullptr;
    CLI::Option* option = nullptr;
    std::string text;
    bool flag = false;
  };
  std::vector<ParameterSlot> parameters;
};

// Hand-written `dmc edit` subcommands for methods outside the registry's shape: tvm edits
// time-varying meshes (varying connectivity) from volume-centre trajectories.
std::vector<Command (*)(CLI::App&)> ExtraEditSubcommands() { return {AddEditTvmSubcommand}; }

nlohmann::json MeasurementsJson(const std::vector<Measurement>& measurements) {
  nlohmann::json list = nlohmann::json::array();
  for (const Measurement& m : measurements) {
    list.push_back({{"frame", m.frame}, {"name", m.name}, {"value", m.value}});
  }
  return list;
}

// Writes the result: geometry through WriteSequence, or, when the method produced per-vertex
// scalars and OUTPUT is a .ply file or a directory, PLY files carrying the scalar and colours.
Status WriteResult(const ProcessingResult& result, const EditArgs& args, bool* scalars_written) {
  const std::filesystem::path output(args.output);
  const std::string extension = LowercaseExtension(output);
  *scalars_written = false;
  if (!result.scalar_name.empty() && extension == ".ply") {
    if (result.sequence.frame_count() != 1) {
      return InvalidArgumentError(
          fmt::format("{} frames cannot go into one .ply file; give a directory as OUTPUT",
                      result.sequence.frame_count()));
    }
    *scalars_written = true;
    return WriteScalarPly(output, result.sequence.triangles(), result.sequence.frame_d(0),
                          result.vertex_scalars[0], result.scalar_name);
  }
  const bool directory =
      extension != ".ply" && extension != ".obj" && extension != ".off" && extension != ".pc2";
  if (!result.scalar_name.empty() && directory) {
    // A directory of per-frame PLYs with the scalar, named like WriteSequence's frames.
    std::error_code error;
    std::filesystem::create_directories(output, error);
    if (error) {
      return IoError(
          fmt::format("cannot create directory {}: {}", output.string(), error.message()));
    }
    for (int f = 0; f < result.sequence.frame_count(); ++f) {
      DMC_RETURN_IF_ERROR(WriteScalarPly(output / fmt::format("frame_{:04d}.ply", f),
                                         result.sequence.triangles(), result.sequence.frame_d(f),
                                         result.vertex_scalars[f], result.scalar_name));
    }
    *scalars_written = true;
    return Status::Ok();
  }
  WriteOptions write_options;
  write_options.frame_format = args.frame_format;
  return WriteSequence(result.sequence, output, write_options);
}

int RunEdit(const MethodInfo& method, const EditArgs& args) {
  const std::string command = fmt::format("edit {}", method.name);
  using Clock = std::chrono::steady_clock;
  RunOptions options;
  options.operator_name = args.operator_name;
  options.operator_frame = args.operator_frame;
  options.operator_options.ddl.mu = args.ddl_mu;
  options.operator_options.geometric.max_cotangent = args.max_cotangent;
  if (args.ddl_reference != "tutte" && args.ddl_reference != "cotan") {
    return ReportError(command,
                       InvalidArgumentError("--ddl-reference must be tutte or cotan, got '" +
                                            args.ddl_reference + "'"),
                       args.json);
  }
  options.operator_options.ddl.reference =
      args.ddl_reference == "cotan" ? DdlReference::kCotan : DdlReference::kTutte;
  for (const EditArgs::ParameterSlot& slot : args.parameters) {
    if (slot.option->count() == 0) continue;
    options.parameters[std::string(slot.spec->name)] =
        slot.spec->type == ParameterType::kFlag ? (slot.flag ? "true" : "false") : slot.text;
  }
  // Cheap checks before reading the input.
  if (const Status distinct =
          RefuseOutputThatIsAnInput(args.output, args.input, "", {args.selection});
      !distinct.ok()) {
    return ReportError(command, distinct, args.json);
  }
  if (Status found = FindOperator(options.operator_name).status(); !found.ok()) {
    return ReportError(command, found, args.json);
  }
  if (Status valid = ParameterValues::Create(method.parameters, options.parameters).status();
      !valid.ok()) {
    return ReportError(command, valid, args.json);
  }
  if (!args.selection.empty()) {
    StatusOr<Selection> selection = ReadSelectionFile(args.selection);
    if (!selection.ok()) return ReportError(command, selection.status(), args.json);
    options.selection = std::move(selection).value();
  } else if (method.needs_selection) {
    return ReportError(
        command, InvalidArgumentError(fmt::format("method {} needs --selection FILE", method.name)),
        args.json);
  }

  WarnIfGltfOptionsUnused(command, args.gltf, {args.input});
  ReadOptions read_options;
  read_options.gltf = args.gltf.options;
  ReadReport report;
  StatusOr<MeshSequence> sequence = ReadSequence(args.input, read_options, &report);
  if (!sequence.ok()) return ReportError(command, sequence.status(), args.json);
  if (!args.json) {
    for (const std::string& warning : report.warnings) ReportWarning(command, warning);
  }

  const auto start = Clock::now();
  StatusOr<PreparedRun> run = Prepare(method.name, *sequence, options);
  if (!run.ok()) return ReportError(command, run.status(), args.json);
  const auto prepared = Clock::now();
  StatusOr<ProcessingResult> result = run->prepared->ApplySequence(*sequence);
  if (!result.ok()) return ReportError(command, result.status(), args.json);
  const auto applied = Clock::now();
  const double precompute_seconds = std::chrono::duration<double>(prepared - start).count();
  const double apply_seconds = std::chrono::duration<double>(applied - prepared).count();

  bool scalars_written = false;
  if (Status written = WriteResult(*result, args, &scalars_written); !written.ok()) {
    return ReportError(command, written, args.json);
  }
  if (!result->scalar_name.empty() && !scalars_written && !args.json) {
    ReportWarning(command, fmt::format("the per-vertex '{}' values need a .ply or directory "
                                       "OUTPUT; only the geometry was written",
                                       result->scalar_name));
  }

  if (args.json) {
    nlohmann::json parameters = nlohmann::json::object();
    for (const auto& [name, value] : run->parameters.values()) parameters[name] = value;
    PrintJson({
        {"method", method.name},
        {"operator", run->laplace ? run->laplace->name : std::string()},
        {"input_frames", sequence->frame_count()},
        {"output_frames", result->sequence.frame_count()},
        {"vertices", sequence->vertex_count()},
        {"parameters", parameters},
        {"precompute_seconds", precompute_seconds},
        {"apply_seconds", apply_seconds},
        {"scalar", result->scalar_name},
        {"measurements", MeasurementsJson(result->measurements)},
        {"output", args.output},
    });
    return 0;
  }
  fmt::print("{}: {} with operator {} on {} frame(s) of {} vertices -> {} ({} frame(s))\n",
             args.input, method.name, run->laplace ? run->laplace->name : "(own)",
             sequence->frame_count(), sequence->vertex_count(), args.output,
             result->sequence.frame_count());
  fmt::print("  precompute {:.4f} s, apply {:.4f} s\n", precompute_seconds, apply_seconds);
  // Per-frame measurements are summarised by their maximum over frames.
  std::map<std::string, double> largest;
  for (const Measurement& m : result->measurements) {
    const auto [it, inserted] = largest.emplace(m.name, m.value);
    if (!inserted) it->second = std::max(it->second, m.value);
  }
  for (const auto& [name, value] : largest) {
    fmt::print("  {:<30}{:.6g}{}\n", name, value,
               sequence->frame_count() > 1 ? " (max over frames)" : "");
  }
  return 0;
}

Command AddMethodSubcommand(CLI::App& edit, const MethodInfo& method) {
  auto args = std::make_shared<EditArgs>();
  CLI::App* app = edit.add_subcommand(std::string(method.name), std::string(method.description));
  app->add_option("input", args->input,
                  "A directory of .obj/.off/.ply frames, a glob such as 'dir/f_*.obj' (quoted), "
                  "one mesh file, a .pc2 cache, or a .glb/.gltf animation")
      ->required();
  app->add_option("-o,--output", args->output,
                  "Output: a mesh file (.obj/.off/.ply, one frame), a .pc2 cache, or a directory "
                  "of frames")
      ->required();
  std::string names;
  for (const OperatorInfo& info : OperatorRegistry()) {
    // The processing methods work on per-vertex operators; spacetime and bspline act on other
    // domains and are refused, so they are not offered.
    if (info.domain != OperatorDomain::kVertex) continue;
    names += (names.empty() ? "" : ", ") + std::string(info.name);
  }
  CLI::Option* operator_option = app->add_option(
      "--operator", args->operator_name,
      method.needs_operator ? "Laplace operator, one for the whole sequence: " + names
                            : "Laplace operator (this method builds its own from it): " + names);
  if (method.needs_operator) operator_option->required();
  app->add_option("--selection", args->selection,
                  "Selection: JSON {\"handles\":[...],\"fixed\":[...],\"transform\":[16 numbers, "
                  "row-major]} (also \"free\", \"anchors\", \"weights\") or a file of handle "
                  "vertex indices")
      ->check(CLI::ExistingFile);
  app->add_option("--operator-frame", args->operator_frame,
                  "Frame the operator is built from (geometric operators); -1: the mean frame. "
                  "DDL operators are always fitted to all frames")
      ->capture_default_str();
  app->add_option("--ddl-mu", args->ddl_mu, "DDL operators: Tikhonov weight")
      ->capture_default_str();
  app->add_option("--ddl-reference", args->ddl_reference, "DDL Tikhonov reference: tutte or cotan")
      ->capture_default_str();
  app->add_option("--max-cotangent", args->max_cotangent,
                  "Geometric operators: the cotangent clamp (cot 1 degree by default; a large "
                  "value turns it off, restoring linear precision next to slivers)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app->add_option("--frame-format", args->frame_format,
                  "Per-frame file format when OUTPUT is a directory: obj, off or ply")
      ->check(CLI::IsMember({"obj", "off", "ply"}))
      ->capture_default_str();
  AddGltfReadOptions(app, &args->gltf);
  app->add_flag("--json", args->json,
                "Print a JSON object: method, operator, input_frames, output_frames, vertices, "
                "parameters, precompute_seconds, apply_seconds, scalar, measurements "
                "[{frame, name, value}], output");
  args->parameters.reserve(method.parameters.size());
  for (const ParameterSpec& spec : method.parameters) {
    EditArgs::ParameterSlot& slot = args->parameters.emplace_back();
    slot.spec = &spec;
    const std::string flag_name = "--" + std::string(spec.name);
    const std::string help = fmt::format("{} (default {})", spec.help,
                                         spec.default_value.empty() ? "\"\"" : spec.default_value);
    if (spec.type == ParameterType::kFlag) {
      slot.option = app->add_flag(flag_name + ",!--no-" + std::string(spec.name), slot.flag, help);
    } else {
      slot.option = app->add_option(flag_name, slot.text, help);
      if (spec.type == ParameterType::kNumber) slot.option->type_name("FLOAT");
      if (spec.type == ParameterType::kInteger) slot.option->type_name("INT");
      if (spec.type == ParameterType::kText) slot.option->type_name("TEXT");
    }
  }
  const MethodInfo* info = &method;
  return {app, [args, info] { return RunEdit(*info, *args); }};
}

}  // namespace

Command AddEditCommand(CLI::App& parent) {
  CLI::App* edit = parent.add_subcommand(
      "edit",
      "Laplacian processing: run METHOD on INPUT (one mesh, or every frame of a sequence with one "
      "operator) and write OUTPUT. `dmc edit METHOD --help` lists a method's options");
  edit->require_subcommand(1);
  auto subcommands = std::make_shared<std::vector<Command>>();
  for (const MethodInfo& method : ProcessingRegistry()) {
    subcommands->push_back(AddMethodSubcommand(*edit, method));
  }
  for (auto add : ExtraEditSubcommands()) subcommands->push_back(add(*edit));
  return {edit, [subcommands] {
            for (const Command& command : *subcommands) {
              if (command.app->parsed()) return command.run();
            }
            return 1;
          }};
}

}  // namespace dmc::cli

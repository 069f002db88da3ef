// dmc edit tvm: edit a time-varying mesh (frames with their own connectivity) through the
// trajectories of its volume centres (dmc/tvm.h): transform selected centres (or vertices),
// inflate/deflate around a centre, or close the sequence into a loop.
//
// The selection file is JSON:
//   transform  {"centres": [i, ...] | "all", "frame": K, "transform": [16 numbers, row-major 4x4]}
//              or {"vertices": [v, ...], "frame": K, "transform": [...]} (vertex-based editing)
//   inflate    {"centre": i, "frame": K, "beta": b}          (b > 0 inflates, b < 0 deflates)
//   loop       {"mode": "automatic"} (the default; {} works too), or
//              {"mode": "semi-automatic", "centres": ..., "frame": 0 | F-1, "transform": [...]}
// each with an optional "decay": {"kind": "none" | "linear" | "smooth", "radius": r (frames)}.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "cli_util.h"
#include "commands.h"
#include "dmc/tvm.h"

namespace dmc::cli {
namespace {

struct EditTvmArgs {
  std::string input;
  std::string centres;
  std::string output;
  std::string operation = "transform";
  std::string selection;
  std::string frame_format = "obj";
  double alpha = 0.0;
  int kabsch_neighbours = 16;
  int surface_neighbours = 8;
  double sigma = 2.0;
  double zeta_degrees = 18.0;
  int subdivide = 0;
  bool unanchored = false;
  bool json = false;
};

using nlohmann::json;

Status SelectionError(const std::string& what) {
  return InvalidArgumentError("selection: " + what);
}

StatusOr<int> ReadInt(const json& selection, const char* key) {
  if (!selection.contains(key)) return SelectionError(std::string("'") + key + "' is missing");
  const json& value = selection[key];
  if (!value.is_number_integer()) {
    return SelectionError(std::string("'") + key + "' must be an integer");
  }
  return value.get<int>();
}

StatusOr<double> ReadNumber(const json& selection, const char* key) {
  if (!selection.contains(key)) return SelectionError(std::string("'") + key + "' is missing");
  const json& value = selection[key];
  if (!value.is_number()) return SelectionError(std::string("'") + key + "' must be a number");
  return value.get<double>();
}

StatusOr<std::vector<int32_t>> ReadIndices(const json& selection, const char* key, int all_count) {
  const json& value = selection[key];
  std::vector<int32_t> indices;
  if (all_count > 0 && value.is_string() && value.get<std::string>() == "all") {
    for (int i = 0; i < all_count; ++i) indices.push_back(i);
    return indices;
  }
  if (!value.is_array()) {
    return SelectionError(std::string("'") + key + "' must be an array of indices" +
                          (all_count > 0 ? " or \"all\"" : ""));
  }
  for (const json& index : value) {
    if (!index.is_number_integer()) {
      return SelectionError(std::string("'") + key + "' holds a non-integer entry");
    }
    indices.push_back(index.get<int32_t>());
  }
  return indices;
}

StatusOr<Eigen::Isometry3d> ReadTransform(const json& selection) {
  if (!selection.contains("transform")) return SelectionError("'transform' is missing");
  const json& value = selection["transform"];
  if (!value.is_array() || value.size() != 16) {
    return SelectionError("'transform' must be 16 numbers (a row-major 4x4 matrix)");
  }
  Eigen::Matrix4d matrix;
  for (int k = 0; k < 16; ++k) {
    if (!value[static_cast<size_t>(k)].is_number()) {
      return SelectionError("'transform' entry " + std::to_string(k) + " is not a number");
    }
    matrix(k / 4, k % 4) = value[static_cast<size_t>(k)].get<double>();
  }
  if ((matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-12) {
    return SelectionError("the last row of 'transform' must be 0 0 0 1");
  }
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.matrix() = matrix;
  DMC_RETURN_IF_ERROR(tvm::CheckRigid(transform, "selection: 'transform'"));
  return transform;
}

StatusOr<tvm::TimeDecay> ReadDecay(const json& selection) {
  tvm::TimeDecay decay;
  if (!selection.contains("decay")) return decay;
  const json& value = selection["decay"];
  if (!value.is_object()) return SelectionError("'decay' must be an object");
  const std::string kind = value.value("kind", "linear");
  if (kind == "none") return decay;
  if (kind == "linear") {
    decay.kind = tvm::DecayKind::kLinear;
  } else if (kind == "smooth") {
    decay.kind = tvm::DecayKind::kSmooth;
  } else {
    return SelectionError("decay kind must be none, linear or smooth, got '" + kind + "'");
  }
  DMC_ASSIGN_OR_RETURN(decay.radius, ReadNumber(value, "radius"));
  return decay;
}

StatusOr<tvm::TransformEdit> ReadTransformEdit(const json& selection, int centre_count) {
  tvm::TransformEdit edit;
  if (!selection.contains("centres")) return SelectionError("'centres' is missing");
  DMC_ASSIGN_OR_RETURN(edit.centres, ReadIndices(selection, "centres", centre_count));
  DMC_ASSIGN_OR_RETURN(edit.frame, ReadInt(selection, "frame"));
  DMC_ASSIGN_OR_RETURN(edit.transform, ReadTransform(selection));
  DMC_ASSIGN_OR_RETURN(edit.decay, ReadDecay(selection));
  return edit;
}

// The centre transforms the selection asks for.
StatusOr<tvm::CentreTransforms> PlanEdit(const tvm::TvmEditor& editor, const std::string& operation,
                                         const json& selection) {
  const int centre_count = editor.graph().centre_count();
  if (operation == "transform") {
    if (selection.contains("vertices")) {
      tvm::VertexEdit edit;
      // "all" is not offered for vertices: that is a transform of every centre.
      DMC_ASSIGN_OR_RETURN(edit.vertices, ReadIndices(selection, "vertices", 0));
      DMC_ASSIGN_OR_RETURN(edit.frame, ReadInt(selection, "frame"));
      DMC_ASSIGN_OR_RETURN(const Eigen::Isometry3d transform, ReadTransform(selection));
      edit.transforms = {transform};
      DMC_ASSIGN_OR_RETURN(edit.decay, ReadDecay(selection));
      return editor.TransformVertices(edit);
    }
    DMC_ASSIGN_OR_RETURN(const tvm::TransformEdit edit, ReadTransformEdit(selection, centre_count));
    return editor.TransformCentres(edit);
  }
  if (operation == "inflate") {
    tvm::InflateEdit edit;
    DMC_ASSIGN_OR_RETURN(edit.centre, ReadInt(selection, "centre"));
    DMC_ASSIGN_OR_RETURN(edit.frame, ReadInt(selection, "frame"));
    DMC_ASSIGN_OR_RETURN(edit.beta, ReadNumber(selection, "beta"));
    DMC_ASSIGN_OR_RETURN(edit.decay, ReadDecay(selection));
    return editor.Inflate(edit);
  }
  tvm::LoopEdit edit;
  const std::string mode = selection.value("mode", "automatic");
  if (mode == "semi-automatic") {
    edit.mode = tvm::LoopMode::kSemiAutomatic;
    DMC_ASSIGN_OR_RETURN(edit.semi, ReadTransformEdit(selection, centre_count));
  } else if (mode != "automatic") {
    return SelectionError("loop mode must be automatic or semi-automatic, got '" + mode + "'");
  }
  DMC_ASSIGN_OR_RETURN(edit.decay, ReadDecay(selection));
  return editor.CloseLoop(edit);
}

double Milliseconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

int RunEditTvm(const EditTvmArgs& args) {
  const auto fail = [&](const Status& status) {
    return ReportError("edit tvm", status, args.json);
  };
  const std::filesystem::path centres_path =
      args.centres.empty() ? std::filesystem::path(args.input) / tvm::kCentresFileName
                           : std::filesystem::path(args.centres);
  // The output directory is written into (frames, stale frames removed, the centres file): it
  // must be none of the inputs nor hold any.
  if (const Status distinct = RefuseOutputThatIsAnInput(args.output, args.input, "",
                                                        {centres_path.string(), args.selection});
      !distinct.ok()) {
    return fail(distinct);
  }
  StatusOr<tvm::TimeVaryingMesh> mesh = tvm::ReadTimeVaryingMesh(args.input);
  if (!mesh.ok()) return fail(mesh.status());
  StatusOr<tvm::CentreTrajectories> centres = tvm::ReadCentres(centres_path);
  if (!centres.ok()) return fail(centres.status());

  StatusOr<std::string> selection_text = [&]() -> StatusOr<std::string> {
    std::FILE* file = std::fopen(args.selection.c_str(), "rb");
    if (file == nullptr) return IoError("cannot read " + args.selection);
    std::string text;
    char buffer[4096];
    for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, file)) > 0;) text.append(buffer, n);
    std::fclose(file);
    return text;
  }();
  if (!selection_text.ok()) return fail(selection_text.status());
  const json selection = json::parse(*selection_text, nullptr, /*allow_exceptions=*/false);
  if (selection.is_discarded() || !selection.is_object()) {
    return fail(ParseError(args.selection + ": not a JSON object"));
  }

  tvm::DeformationOptions options;
  options.affinity.alpha = args.alpha;
  options.kabsch_neighbours = args.kabsch_neighbours;
  options.surface.neighbours = args.surface_neighbours;
  options.surface.sigma = args.sigma;
  options.surface.subdivision_angle = args.zeta_degrees * std::numbers::pi / 180.0;
  options.surface.subdivision_iterations = args.subdivide;
  options.anchor_to_identity = !args.unanchored;

  auto start = std::chrono::steady_clock::now();
  StatusOr<tvm::TvmEditor> editor =
      tvm::TvmEditor::Create(std::move(mesh).value(), std::move(centres).value(), options);
  if (!editor.ok()) return fail(editor.status());
  const double affinity_ms = Milliseconds(start);
  start = std::chrono::steady_clock::now();
  StatusOr<tvm::CentreTransforms> transforms = PlanEdit(*editor, args.operation, selection);
  if (!transforms.ok()) return fail(transforms.status());
  const double centres_ms = Milliseconds(start);
  start = std::chrono::steady_clock::now();
  StatusOr<tvm::EditResult> result = editor->Apply(*transforms);
  if (!result.ok()) return fail(result.status());
  const double surface_ms = Milliseconds(start);

  const std::filesystem::path output = args.output;
  Status written = tvm::WriteTimeVaryingMesh(result->mesh, output, args.frame_format);
  if (written.ok()) written = tvm::WriteCentres(result->centres, output / tvm::kCentresFileName);
  if (!written.ok()) return fail(written);

  double max_centre_move = 0.0;
  const tvm::CentreTrajectories& original = editor->graph().centres();
  for (int f = 0; f < original.frame_count(); ++f) {
    max_centre_move = std::max(max_centre_move, (result->centres.positions[static_cast<size_t>(f)] -
                                                 original.positions[static_cast<size_t>(f)])
                                                    .rowwise()
                                                    .norm()
                                                    .maxCoeff());
  }
  if (args.json) {
    PrintJson({{"operation", args.operation},
               {"frames", result->mesh.frame_count()},
               {"centres", original.centre_count()},
               {"alpha", editor->graph().alpha()},
               {"vertices_added", result->vertices_added},
               {"max_centre_displacement", max_centre_move},
               {"milliseconds",
                {{"affinity", affinity_ms}, {"centres", centres_ms}, {"surface", surface_ms}}},
               {"output", args.output}});
  } else {
    fmt::print(
        "{}: {} frame(s), {} centres (alpha {:.4g}); centres moved up to {:.4g}; {} vertices "
        "added by subdivision -> {}\n",
        args.operation, result->mesh.frame_count(), original.centre_count(),
        editor->graph().alpha(), max_centre_move, result->vertices_added, args.output);
  }
  return 0;
}

}  // namespace

Command AddEditTvmSubcommand(CLI::App& edit) {
  auto args = std::make_shared<EditTvmArgs>();
  CLI::App* app = edit.add_subcommand(
      "tvm",
      "Edit a time-varying mesh (frames with their own connectivity) through its volume-centre "
      "trajectories, with dual quaternions");
  app->footer(
      "INPUT is a directory of frame files; OUTPUT gets the edited frames and centres.txt (the "
      "edited centres). The selection JSON is\n"
      "  transform: {\"centres\": [i, ...] | \"all\", \"frame\": K, \"transform\": [16 numbers, "
      "row-major 4x4]}\n"
      "             or {\"vertices\": [v, ...], \"frame\": K, \"transform\": [...]}\n"
      "  inflate:   {\"centre\": i, \"frame\": K, \"beta\": b}   (b < 0 deflates)\n"
      "  loop:      {\"mode\": \"automatic\"} or {\"mode\": \"semi-automatic\", \"centres\": ..., "
      "\"frame\": 0 | F-1, \"transform\": [...]}\n"
      "each with an optional \"decay\": {\"kind\": \"none\" | \"linear\" | \"smooth\", \"radius\": "
      "r}.");
  app->add_option("input", args->input, "Directory of frame files (.obj/.off/.ply)")->required();
  app->add_option("--centres", args->centres,
                  "Centres file (dmc-centres text format; default INPUT/centres.txt)");
  app->add_option("-o,--output", args->output, "Output directory")->required();
  app->add_option("--operation", args->operation, "transform | inflate | loop")
      ->check(CLI::IsMember({"transform", "inflate", "loop"}))
      ->capture_default_str();
  app->add_option("--selection", args->selection, "Selection JSON file (see above)")->required();
  app->add_option("--alpha", args->alpha,
                  "Affinity shape parameter alpha (0: 1 / median centre spacing)")
      ->capture_default_str();
  app->add_option("--kabsch-neighbours", args->kabsch_neighbours,
                  "K: most affine centres in each inter-frame Kabsch fit")
      ->capture_default_str();
  app->add_option("--surface-neighbours", args->surface_neighbours,
                  "k: the nearest centre plus its k-1 most affine ones per vertex")
      ->capture_default_str();
  app->add_option("--sigma", args->sigma, "Smoothness of the smooth-minimum surface weights")
      ->capture_default_str();
  app->add_option("--subdivide", args->subdivide,
                  "S: rounds of adaptive edge subdivision (0 = off)")
      ->capture_default_str();
  app->add_option("--zeta", args->zeta_degrees,
                  "Split edges whose ends' relative rotation exceeds this angle (degrees)")
      ->capture_default_str();
  app->add_flag("--unanchored", args->unanchored,
                "Blend transforms within the edited frame by Eq. (2) alone, without the "
                "identity where the effectors' affinity fades (every affine centre follows)");
  app->add_option("--frame-format", args->frame_format, "Output frame file format")
      ->check(CLI::IsMember({"obj", "off", "ply"}))
      ->capture_default_str();
  app->add_flag("--json", args->json, "Print a JSON summary instead of text");
  return {app, [args] { return RunEditTvm(*args); }};
}

}  // namespace dmc::cli

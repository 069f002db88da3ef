// dmc.edit and dmc.methods: the Laplacian processing registry (dmc/processing.h) on NumPy arrays.
#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "arrays.h"
#include "bindings.h"
#include "dmc/processing.h"
#include "errors.h"

namespace dmc::python {
namespace {

// Method parameters are declared with dashes ("anchor-weight", the CLI's --anchor-weight); Python
// keywords use underscores (anchor_weight=).
std::string PythonKeyword(std::string_view parameter) {
  std::string keyword(parameter);
  std::replace(keyword.begin(), keyword.end(), '-', '_');
  return keyword;
}

std::string_view ParameterTypeName(ParameterType type) {
  switch (type) {
    case ParameterType::kNumber:
      return "number";
    case ParameterType::kInteger:
      return "integer";
    case ParameterType::kText:
      return "text";
    case ParameterType::kFlag:
      return "flag";
  }
  return "unknown";
}

py::list MethodTable() {
  py::list table;
  for (const MethodInfo& info : ProcessingRegistry()) {
    py::list parameters;
    for (const ParameterSpec& spec : info.parameters) {
      py::dict parameter;
      parameter["name"] = std::string(spec.name);
      parameter["keyword"] = PythonKeyword(spec.name);
      parameter["type"] = std::string(ParameterTypeName(spec.type));
      parameter["default"] = std::string(spec.default_value);
      parameter["help"] = std::string(spec.help);
      parameters.append(parameter);
    }
    py::dict row;
    row["name"] = std::string(info.name);
    row["description"] = std::string(info.description);
    row["scope"] = info.scope == MethodScope::kPerFrame ? "per-frame" : "whole-sequence";
    row["needs_operator"] = info.needs_operator;
    row["needs_selection"] = info.needs_selection;
    row["vertex_scalar"] = info.vertex_scalar.empty()
                               ? py::object(py::none())
                               : py::object(py::str(std::string(info.vertex_scalar)));
    row["parameters"] = parameters;
    table.append(row);
  }
  return table;
}

// A keyword argument's value as the text ParameterValues parses: bool as true/false (checked
// before int: bool is an int subclass), numbers by Python's shortest round-trip repr, str as is.
std::string ParameterText(const std::string& keyword, const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  const py::object numbers = py::module_::import("numbers");
  if (py::isinstance(value, numbers.attr("Integral"))) {
    return py::str(py::int_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
  }
  if (py::isinstance(value, numbers.attr("Real"))) {
    return py::repr(py::float_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
  }
  ThrowInvalidArgument(fmt::format("parameter {}= must be a number, a bool or a str, got {}",
                                   keyword, py::str(py::type::of(value)).cast<std::string>()));
}

// The selection argument: None, a dict in the JSON form of dmc/processing.h (lists may be NumPy
// arrays), a JSON string starting with '{', or a path to a selection file.
Selection SelectionFromObject(const py::handle& object) {
  if (object.is_none()) return {};
  if (py::isinstance<py::dict>(object)) {
    const py::object to_list = py::cpp_function([](const py::handle& value) -> py::object {
      if (py::hasattr(value, "tolist")) return value.attr("tolist")();
      throw py::type_error("selection values must be lists, numbers or NumPy arrays, got " +
                           py::str(py::type::of(value)).cast<std::string>());
    });
    std::string text;
    try {
      text = py::module_::import("json")
                 .attr("dumps")(object, py::arg("default") = to_list)
                 .cast<std::string>();
    } catch (py::error_already_set& error) {
      ThrowInvalidArgument(std::string("selection cannot be written as JSON: ") + error.what());
    }
    return ValueOrThrow(ParseSelectionJson(text));
  }
  if (py::isinstance<py::str>(object)) {
    const std::string text = object.cast<std::string>();
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && text[first] == '{') {
      return ValueOrThrow(ParseSelectionJson(text));
    }
  }
  if (py::isinstance<py::str>(object) ||
      py::isinstance(object, py::module_::import("os").attr("PathLike"))) {
    const std::string path = py::module_::import("os").attr("fspath")(object).cast<std::string>();
    py::gil_scoped_release release;
    return ValueOrThrow(ReadSelectionFile(path));
  }
  ThrowInvalidArgument(
      "selection must be None, a dict, a JSON string or a path to a selection "
      "file, got " +
      py::str(py::type::of(object)).cast<std::string>());
}

py::dict MeasurementsAndScalars(const ProcessingResult& result) {
  py::list measurements;
  for (const Measurement& m : result.measurements) {
    py::dict row;
    row["frame"] = m.frame;
    row["name"] = m.name;
    row["value"] = m.value;
    measurements.append(row);
  }
  py::dict details;
  details["measurements"] = measurements;
  if (result.scalar_name.empty() || result.vertex_scalars.empty()) {
    details["scalar_name"] = py::none();
    details["scalars"] = py::none();
    return details;
  }
  const py::ssize_t frames = static_cast<py::ssize_t>(result.vertex_scalars.size());
  const py::ssize_t vertices = result.vertex_scalars.front().size();
  py::array_t<double> scalars({frames, vertices});
  auto view = scalars.mutable_unchecked<2>();
  for (py::ssize_t f = 0; f < frames; ++f) {
    const Eigen::VectorXd& values = result.vertex_scalars[static_cast<size_t>(f)];
    if (values.size() != vertices) {
      throw StatusError(InternalError(fmt::format(
          "method returned {} scalars for frame {}, expected {}", values.size(), f, vertices)));
    }
    for (py::ssize_t v = 0; v < vertices; ++v) view(f, v) = values[v];
  }
  details["scalar_name"] = result.scalar_name;
  details["scalars"] = std::move(scalars);
  return details;
}

py::object EditBinding(const std::string& method, const py::handle& frames, const py::handle& faces,
                       const std::string& operator_name, int operator_frame,
                       const py::handle& selection, double ddl_mu, const std::string& ddl_reference,
                       bool return_details, const py::handle& parameter_dict,
                       const py::kwargs& parameters) {
  RunOptions options;
  options.operator_name = operator_name;
  options.operator_frame = operator_frame;
  options.operator_options.ddl.mu = ddl_mu;
  if (ddl_reference != "tutte" && ddl_reference != "cotan") {
    ThrowInvalidArgument("ddl_reference must be \"tutte\" or \"cotan\", got \"" + ddl_reference +
                         "\"");
  }
  options.operator_options.ddl.reference =
      ddl_reference == "cotan" ? DdlReference::kCotan : DdlReference::kTutte;
  // Method parameters as keywords, or in `parameters` for those named like edit()'s own
  // arguments (morph's "frames"); both may not name the same one.
  const auto add_parameter = [&](const py::handle& key, const py::handle& value) {
    const std::string keyword = py::str(key).cast<std::string>();
    std::string name = keyword;
    std::replace(name.begin(), name.end(), '_', '-');
    if (options.parameters.count(name) > 0) {
      ThrowInvalidArgument("method parameter " + keyword + " is given twice");
    }
    options.parameters[name] = ParameterText(keyword, value);
  };
  if (!parameter_dict.is_none()) {
    if (!py::isinstance<py::dict>(parameter_dict)) {
      ThrowInvalidArgument("parameters must be a dict of method parameters, got " +
                           std::string(py::str(py::type::of(parameter_dict))));
    }
    for (const auto& [key, value] : parameter_dict.cast<py::dict>()) add_parameter(key, value);
  }
  for (const auto& [key, value] : parameters) add_parameter(key, value);
  options.selection = SelectionFromObject(selection);
  const bool one_mesh = py::array(py::module_::import("numpy").attr("asarray")(frames)).ndim() == 2;
  MeshSequence sequence = SequenceFromArrays(frames, faces, "frames");
  std::optional<ProcessingResult> result;
  {
    py::gil_scoped_release release;
    ValidateOrThrow(sequence);
    result = ValueOrThrow(RunMethod(method, sequence, options));
  }
  py::dict details = MeasurementsAndScalars(*result);
  py::tuple arrays = SequenceToArrays(std::move(result->sequence));
  py::object out_frames = arrays[0];
  // A (V, 3) input gets a (V, 3) output, as one would expect from editing one mesh.
  if (one_mesh && out_frames.attr("shape").cast<py::tuple>()[0].cast<py::ssize_t>() == 1) {
    out_frames = out_frames[py::int_(0)];
    if (!details["scalars"].is_none()) details["scalars"] = details["scalars"][py::int_(0)];
  }
  if (!return_details) return py::make_tuple(out_frames, arrays[1]);
  return py::make_tuple(out_frames, arrays[1], details);
}

constexpr const char* kEditDoc =
    R"(edit(method, frames, faces, *, operator="cotan", operator_frame=-1, selection=None, ddl_mu=0.0, ddl_reference="tutte", return_details=False, parameters=None, **method_parameters) -> (frames, faces)

Runs a Laplacian processing method of the registry (dmc.methods(): editing, smoothing, ...) on a
mesh or a whole sequence, like `dmc edit METHOD`. One Laplace operator is built for the whole
sequence (from the mean frame, or frame `operator_frame`; a DDL operator is fitted to all frames)
and every frame is processed with the same precomputed factorisation, so results stay
temporally consistent.

Args:
    method: registry name, e.g. "laplacian-edit".
    frames: float32 array (F, V, 3), or (V, 3) for one mesh (the result then is (V, 3) too).
    faces: int32 array (T, 3).
    operator: Laplace operator name (dmc.operators()).
    operator_frame: -1 = mean frame as the geometric reference; f >= 0 = frame f.
    selection: which vertices are handles / fixed and how handles move: a dict in the JSON form
        {"handles": [...], "fixed": [...], "transform": [16 numbers, row-major 4x4], optional
        "free", "anchors", "weights"} (lists may be NumPy arrays), the same as a JSON string, or
        a path to a selection file (JSON, or whitespace-separated handle indices).
    ddl_mu, ddl_reference: Tikhonov weight and reference ("tutte" or "cotan") of DDL operators.
    return_details: also return a dict with "measurements" (list of {frame, name, value}),
        "scalar_name" and "scalars" (float64 (F, V) per-vertex output, or None).
    **method_parameters: the method's own parameters (see dmc.methods()), dashes written as
        underscores: anchor_weight=2.0 for --anchor-weight. Numbers, bools and str are accepted.
    parameters: the same as a dict, for a parameter named like one of edit()'s own arguments:
        dmc.edit("morph", frames, faces, parameters={"frames": 21}) (a `frames=21` keyword
        would be edit()'s frames).

Returns:
    (frames, faces), or (frames, faces, details). The faces are the input's.

Raises:
    dmc.Error: NOT_FOUND (unknown method, operator or parameter; the message lists the known
        ones), INVALID_ARGUMENT (bad selection or parameter value), NUMERICAL_FAILURE,
        UNSUPPORTED (a mesh the method cannot handle).
)";

constexpr const char* kMethodsDoc = R"(methods() -> list[dict]

The processing registry, in its fixed order: one dict per method with name, description, scope
("per-frame" or "whole-sequence"), needs_operator, needs_selection, vertex_scalar (name of the
per-vertex output, or None) and parameters (list of {name, keyword, type, default, help}; pass
them to dmc.edit() as keyword=value).
)";

}  // namespace

void RegisterEdit(py::module_& module) {
  module.def("edit", &EditBinding, WithTextSignature(kEditDoc).c_str(), py::arg("method"),
             py::arg("frames"), py::arg("faces"), py::kw_only(), py::arg("operator") = "cotan",
             py::arg("operator_frame") = -1, py::arg("selection") = py::none(),
             py::arg("ddl_mu") = 0.0, py::arg("ddl_reference") = "tutte",
             py::arg("return_details") = false, py::arg("parameters") = py::none());
  module.def("methods", &MethodTable, WithTextSignature(kMethodsDoc).c_str());
}

}  // namespace dmc::python

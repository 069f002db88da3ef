// dmc.metrics, dmc.laplacian, dmc.operators: distortion metrics and Laplace operators on NumPy
// arrays.
#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "arrays.h"
#include "bindings.h"
#include "dmc/metrics.h"
#include "dmc/operators.h"
#include "dmc/pca.h"
#include "errors.h"

namespace dmc::python {
namespace {

py::dict DistortionToDict(const DistortionReport& report) {
  py::dict out;
  out["kg"] = report.kg;
  out["sted"] = report.sted;
  out["sted_s"] = report.sted_s;
  out["sted_t"] = report.sted_t;
  out["rmse_rel"] = report.rmse_rel;
  out["max_error"] = report.max_error;
  out["frames"] = report.frames;
  out["vertices"] = report.vertices;
  return out;
}

py::dict MetricsBinding(const py::handle& original_frames, const py::handle& distorted_frames,
                        const py::handle& faces, const StedOptions& options) {
  const MeshSequence original = SequenceFromArrays(original_frames, faces, "original");
  const MeshSequence distorted = SequenceFromArrays(distorted_frames, faces, "distorted");
  DistortionReport report;
  {
    py::gil_scoped_release release;
    // MeasureDistortion validates both sequences and the options itself.
    report = ValueOrThrow(MeasureDistortion(original, distorted, options));
  }
  return DistortionToDict(report);
}

struct LaplacianParams {
  std::string operator_name;
  int rank = 0;
  double mu = 0.0;
  std::string reference;
  int reference_frame = -1;
  GeometricOptions geometric;
};

// Builds the operator exactly as `dmc laplacian` does for the same parameters.
LaplaceOperator BuildLaplacian(const MeshSequence& sequence, const LaplacianParams& params) {
  ValidateOrThrow(sequence);
  const OperatorInfo* info = ValueOrThrow(FindOperator(params.operator_name));
  if (params.rank < 0) ThrowInvalidArgument("rank must be >= 0 (0: all frames)");
  if (!(params.mu >= 0.0) || !std::isfinite(params.mu)) {
    ThrowInvalidArgument(fmt::format("mu must be a finite value >= 0, got {}", params.mu));
  }
  if (params.reference != "tutte" && params.reference != "cotan") {
    ThrowInvalidArgument("reference must be \"tutte\" or \"cotan\", got \"" + params.reference +
                         "\"");
  }
  if (params.reference_frame < -1 || params.reference_frame >= sequence.frame_count()) {
    ThrowInvalidArgument(
        fmt::format("reference_frame {} but the sequence has {} frame(s) "
                    "(-1 = the mean frame)",
                    params.reference_frame, sequence.frame_count()));
  }
  const MeshTopology topology = BuildTopology(sequence.triangles(), sequence.vertex_count());
  OperatorSource source = SourceFromSequence(sequence, params.reference_frame);
  if (info->needs_trajectories && params.rank > 0) {
    TrajectoryPca pca = ValueOrThrow(ComputeTrajectoryPca(sequence, params.rank));
    source.trajectories = std::move(pca.coefficients);
  }
  OperatorOptions options;
  options.geometric = params.geometric;
  options.ddl.mu = params.mu;
  options.ddl.reference = params.reference == "cotan" ? DdlReference::kCotan : DdlReference::kTutte;
  return ValueOrThrow(BuildOperator(info->name, topology, source, options));
}

// scipy.sparse.csr_matrix when SciPy imports, else the (data, indices, indptr) triple.
py::object SparseResult(const LaplaceOperator& op) {
  const py::tuple csr = CsrArrays(op.matrix);
  try {
    const py::module_ sparse = py::module_::import("scipy.sparse");
    const py::ssize_t size = op.matrix.rows();
    return sparse.attr("csr_matrix")(csr, py::arg("shape") = py::make_tuple(size, size));
  } catch (py::error_already_set& error) {
    if (!error.matches(PyExc_ImportError)) throw;
    return csr;
  }
}

py::object LaplacianBinding(const py::handle& frames, const py::handle& faces,
                            const LaplacianParams& params, bool return_mass) {
  const MeshSequence sequence = SequenceFromArrays(frames, faces, "frames_or_mesh");
  std::optional<LaplaceOperator> op;
  {
    py::gil_scoped_release release;
    op = BuildLaplacian(sequence, params);
  }
  py::object matrix = SparseResult(*op);
  if (!return_mass) return matrix;
  py::object mass = op->mass.size() > 0 ? py::object(VectorToArray(op->mass)) : py::none();
  return py::make_tuple(std::move(matrix), std::move(mass));
}

py::list OperatorTable() {
  py::list table;
  for (const OperatorInfo& info : OperatorRegistry()) {
    py::dict row;
    row["name"] = std::string(info.name);
    row["wire_id"] =
        info.wire_id ? py::object(py::int_(static_cast<int>(*info.wire_id))) : py::none();
    row["description"] = std::string(info.description);
    row["domain"] = std::string(OperatorDomainName(info.domain));
    row["needs_geometry"] = info.needs_geometry;
    row["needs_trajectories"] = info.needs_trajectories;
    row["symmetric"] = info.symmetric;
    row["unit_sum"] = info.unit_sum;
    table.append(row);
  }
  return table;
}

constexpr const char* kMetricsDoc =
    R"(metrics(original, distorted, faces, *, sted_width=1, ...) -> dict

Distortion of `distorted` against `original` (the same values as `dmc metrics --json`): KG error,
STED with its spatial and temporal parts, RMSE relative to the bounding-box diagonal, maximum
vertex error. The original defines STED's edge lengths, diameter and local speed, so the order
matters.

Args:
    original: float32 array (F, V, 3) or (V, 3), the reference.
    distorted: array of the same shape.
    faces: int32 array (T, 3) shared by both.
    sted_width: STED neighbourhood width w in one-ring steps (>= 0).
    sted_dt: STED frame distance dt (>= 0).
    sted_window: STED speed window s in frames (>= 1).
    sted_c: STED weight c of the temporal part (>= 0).

Returns:
    dict with kg, sted, sted_s, sted_t, rmse_rel, max_error (floats), frames, vertices (ints).

Raises:
    dmc.Error: MISMATCH (different shapes), INVALID_SEQUENCE (invalid mesh, or an original so
        degenerate that a metric is undefined), INVALID_ARGUMENT (STED option out of range).
)";

constexpr const char* kLaplacianDoc =
    R"(laplacian(frames_or_mesh, faces, operator="cotan", *, ...) -> scipy.sparse.csr_matrix

Builds a discrete Laplace operator L (V x V), the same matrix `dmc laplacian` reports on. Sign
convention: L_ij = w_ij on edges, L_ii = -sum_j w_ij, so (L @ X)_i = sum_j w_ij (x_j - x_i) and
every row sums to zero.

Args:
    frames_or_mesh: float32 array (F, V, 3) (a sequence) or (V, 3) (one mesh).
    faces: int32 array (T, 3).
    operator: kirchhoff, tutte, cotan, cotan-area, cotan-sym, mean-value, ddl, ddl-asym, or any
        other name of dmc.operators().
    rank: DDL operators: fit to the sequence's PCA coefficients of this rank; 0 fits to the
        positions of all frames.
    mu: DDL operators: Tikhonov weight toward the reference operator (>= 0).
    reference: DDL Tikhonov reference, "tutte" or "cotan".
    reference_frame: geometric operators: frame to build from; -1 = the mean frame.
    max_cotangent: cotangents are clamped to [-max_cotangent, max_cotangent] (default cot 1 deg).
    return_mass: also return the diagonal mass matrix (vertex areas) as a float64 array of length
        V, or None for operators without one (only the cotangent operators have one).

Returns:
    scipy.sparse.csr_matrix (float64, int32 indices), or when SciPy cannot be imported the
    (data, indices, indptr) triple of that CSR matrix. With return_mass: (matrix, mass).

Raises:
    dmc.Error: NOT_FOUND (unknown operator; the message lists the known ones), INVALID_ARGUMENT,
        INVALID_SEQUENCE, NUMERICAL_FAILURE (a DDL fit failed).
)";

constexpr const char* kOperatorsDoc = R"(operators() -> list[dict]

The Laplace operator registry, in its fixed order: one dict per operator with name, wire_id (the
frozen stream ID, or None when a decoder cannot rebuild it), description, domain ("vertex": a V×V
matrix; "spacetime": V·F×V·F over all frames; "element": B-spline elements), needs_geometry,
needs_trajectories, symmetric, unit_sum. laplacian() builds the "vertex" operators; those with a
wire_id are valid for encode().
)";

}  // namespace

void RegisterAnalysis(py::module_& module) {
  const StedOptions sted_defaults;
  module.def(
      "metrics",
      [](const py::handle& original, const py::handle& distorted, const py::handle& faces,
         int sted_width, double sted_dt, int sted_window, double sted_c) {
        StedOptions options;
        options.width = sted_width;
        options.dt = sted_dt;
        options.window = sted_window;
        options.c = sted_c;
        return MetricsBinding(original, distorted, faces, options);
      },
      WithTextSignature(
          "metrics(original, distorted, faces, *, sted_width=" + Repr(sted_defaults.width) +
          ", sted_dt=" + Repr(sted_defaults.dt) + ", sted_window=" + Repr(sted_defaults.window) +
          ", sted_c=" + Repr(sted_defaults.c) + ") -> dict" + AfterFirstLine(kMetricsDoc))
          .c_str(),
      py::arg("original"), py::arg("distorted"), py::arg("faces"), py::kw_only(),
      py::arg("sted_width") = sted_defaults.width, py::arg("sted_dt") = sted_defaults.dt,
      py::arg("sted_window") = sted_defaults.window, py::arg("sted_c") = sted_defaults.c);

  const GeometricOptions geometric_defaults;
  module.def(
      "laplacian",
      [](const py::handle& frames, const py::handle& faces, const std::string& operator_name,
         int rank, double mu, const std::string& reference, int reference_frame,
         double max_cotangent, bool return_mass) {
        LaplacianParams params;
        params.operator_name = operator_name;
        params.rank = rank;
        params.mu = mu;
        params.reference = reference;
        params.reference_frame = reference_frame;
        params.geometric.max_cotangent = max_cotangent;
        return LaplacianBinding(frames, faces, params, return_mass);
      },
      WithTextSignature("laplacian(frames_or_mesh, faces, operator='cotan', *, rank=0, mu=0.0, "
                        "reference='tutte', reference_frame=-1, max_cotangent=" +
                        Repr(geometric_defaults.max_cotangent) +
                        ", return_mass=False) -> scipy.sparse.csr_matrix" +
                        AfterFirstLine(kLaplacianDoc))
          .c_str(),
      py::arg("frames_or_mesh"), py::arg("faces"), py::arg("operator") = "cotan", py::kw_only(),
      py::arg("rank") = 0, py::arg("mu") = 0.0, py::arg("reference") = "tutte",
      py::arg("reference_frame") = -1, py::arg("max_cotangent") = geometric_defaults.max_cotangent,
      py::arg("return_mass") = false);

  module.def("operators", &OperatorTable, WithTextSignature(kOperatorsDoc).c_str());
}

}  // namespace dmc::python

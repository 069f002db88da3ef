// morph: morphing between two frames through their differential coordinates (Alexa 2003;
// thesis 3.5). Output: `frames` meshes at t = 0, 1/(frames−1), ..., 1.
//
// δ(t) interpolates δ1 = L·x1 and δ2 = L·x2 linearly or with separate length and Rodrigues
// rotation interpolation (InterpolateDeltas). The positions then solve, with the constrained
// columns eliminated (as in laplacian-edit's hard mode),
//   min ‖L_U x_U − (δ(t) − L_C x_C(t))‖²,
// where the constrained set C is
//  - partial morph (a selection is given): the handles, at (1 − t)·x1 + t·x2 (thesis formula
//    3.4), and the fixed vertices, at x1; the free vertices carry the morphed detail;
//  - whole-mesh morph (no selection): one vertex per connected component at its linearly
//    interpolated position, after which each component is translated so its centroid is the
//    interpolated centroid (δ says nothing about translation).
// With linear interpolation a whole-mesh morph reproduces linear position interpolation exactly
// (L is linear), which the tests check; rotation interpolation keeps details from collapsing
// where δ1 and δ2 point in different directions. One operator (built once, by default from the
// mean frame) serves both meshes, as the method requires.
#include <fmt/format.h>

#include <cmath>

#include "dmc/processing.h"
#include "processing/processing_util.h"

namespace dmc {

Eigen::MatrixXd InterpolateDeltas(const Eigen::MatrixXd& from, const Eigen::MatrixXd& to, double t,
                                  DeltaInterpolation mode) {
  Eigen::MatrixXd result = (1.0 - t) * from + t * to;
  if (mode == DeltaInterpolation::kLinear) return result;
  for (Eigen::Index i = 0; i < from.rows(); ++i) {
    const Eigen::Vector3d d1 = from.row(i).transpose(), d2 = to.row(i).transpose();
    const double l1 = d1.norm(), l2 = d2.norm();
    if (!(l1 > 1e-300) || !(l2 > 1e-300)) continue;  // zero vector: no direction, keep linear
    const double length = (1.0 - t) * l1 + t * l2;
    const Eigen::Vector3d cross = d1.cross(d2);
    const double sine = cross.norm(), cosine = d1.dot(d2);
    Eigen::Vector3d axis;
    if (sine > 1e-12 * l1 * l2) {
      axis = cross / sine;
    } else if (cosine > 0.0) {
      result.row(i) = (length / l1) * d1.transpose();  // parallel: no rotation
      continue;
    } else {
      // Antiparallel: every axis perpendicular to d1 is a shortest rotation; pick a stable one.
      const Eigen::Vector3d helper =
          std::abs(d1.x()) < 0.9 * l1 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
      axis = d1.cross(helper).normalized();
    }
    const double angle = std::atan2(sine, cosine);
    const Eigen::Vector3d rotated =
        d1 * std::cos(angle * t) + axis.cross(d1) * std::sin(angle * t);  // |rotated| = l1
    result.row(i) = (length / rotated.norm()) * rotated.transpose();
  }
  return result;
}

namespace {

class PreparedMorph final : public PreparedMethod {
 public:
  struct State {
    SparseMatrixD laplacian;
    std::vector<int> free_vertices;
    std::vector<int> constrained_vertices;  // handles, then fixed (partial) or component pins
    int handle_count = 0;                   // leading constrained vertices that interpolate
    bool whole_mesh = false;
    std::vector<int> component_of_vertex;
    int component_count = 0;
    SparseMatrixD free_columns_transpose;
    SparseMatrixD constrained_columns;
    int from = 0, to = 0, frames = 2;
    DeltaInterpolation interpolation = DeltaInterpolation::kLinear;
  };

  PreparedMorph(State state, SparseSpdSolver solver)
      : state_(std::move(state)), solver_(std::move(solver)) {}

  StatusOr<ProcessingResult> ApplySequence(const MeshSequence& sequence) const override {
    const State& s = state_;
    if (s.from >= sequence.frame_count() || s.to >= sequence.frame_count() ||
        sequence.vertex_count() != s.laplacian.rows()) {
      return MismatchError("the sequence differs from the one the morph was prepared for");
    }
    const Eigen::MatrixXd x1 = processing::ToDense(sequence.frame_d(s.from));
    const Eigen::MatrixXd x2 = processing::ToDense(sequence.frame_d(s.to));
    const Eigen::MatrixXd delta1 = s.laplacian * x1, delta2 = s.laplacian * x2;
    ProcessingResult result;
    result.sequence = MeshSequence(sequence.vertex_count(), sequence.triangles(), 0);
    result.sequence.name = sequence.name;
    result.sequence.frame_rate = sequence.frame_rate;
    for (int k = 0; k < s.frames; ++k) {
      const double t = static_cast<double>(k) / (s.frames - 1);
      const Eigen::MatrixXd linear = (1.0 - t) * x1 + t * x2;
      const Eigen::MatrixXd delta = InterpolateDeltas(delta1, delta2, t, s.interpolation);
      Eigen::MatrixXd targets(s.constrained_vertices.size(), 3);
      for (size_t c = 0; c < s.constrained_vertices.size(); ++c) {
        const int v = s.constrained_vertices[c];
        const bool moves = s.whole_mesh || static_cast<int>(c) < s.handle_count;
        targets.row(static_cast<Eigen::Index>(c)) = moves ? linear.row(v) : x1.row(v);
      }
      Eigen::MatrixXd x = linear;
      if (!s.free_vertices.empty()) {
        const Eigen::MatrixXd rhs =
            s.free_columns_transpose * (delta - s.constrained_columns * targets);
        DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd solved, solver_.Solve(rhs));
        for (size_t i = 0; i < s.free_vertices.size(); ++i) {
          x.row(s.free_vertices[i]) = solved.row(static_cast<Eigen::Index>(i));
        }
      }
      for (size_t c = 0; c < s.constrained_vertices.size(); ++c) {
        x.row(s.constrained_vertices[c]) = targets.row(static_cast<Eigen::Index>(c));
      }
      if (s.whole_mesh) CentreComponents(linear, x);
      DMC_RETURN_IF_ERROR(result.sequence.AppendFrame(x.cast<float>()));
      result.measurements.push_back({k, "t", t});
      result.measurements.push_back(
          {k, "distance_to_linear", (x - linear).rowwise().norm().maxCoeff()});
    }
    return result;
  }

 private:
  // Translates each component of x so its centroid matches that of `reference`.
  void CentreComponents(const Eigen::MatrixXd& reference, Eigen::MatrixXd& x) const {
    const State& s = state_;
    Eigen::MatrixXd shift = Eigen::MatrixXd::Zero(s.component_count, 3);
    Eigen::VectorXd count = Eigen::VectorXd::Zero(s.component_count);
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      shift.row(s.component_of_vertex[v]) += reference.row(v) - x.row(v);
      count[s.component_of_vertex[v]] += 1.0;
    }
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      const int c = s.component_of_vertex[v];
      x.row(v) += shift.row(c) / count[c];
    }
  }

  State state_;
  SparseSpdSolver solver_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  PreparedMorph::State state;
  const int frame_count = context.sequence.frame_count();
  DMC_ASSIGN_OR_RETURN(state.from, context.parameters.Integer("from"));
  DMC_ASSIGN_OR_RETURN(state.to, context.parameters.Integer("to"));
  DMC_ASSIGN_OR_RETURN(state.frames, context.parameters.Integer("frames"));
  DMC_ASSIGN_OR_RETURN(const std::string interpolation, context.parameters.Text("interpolation"));
  if (state.to < 0) state.to += frame_count;  // -1 = the last frame
  if (state.from < 0 || state.from >= frame_count || state.to < 0 || state.to >= frame_count) {
    return InvalidArgumentError(
        fmt::format("--from {} / --to {} must name frames of the {}-frame "
                    "input (negative --to counts from the end)",
                    state.from, state.to, frame_count));
  }
  if (state.frames < 2 || state.frames > 100000) {
    return InvalidArgumentError("--frames must be in [2, 100000]");
  }
  if (interpolation == "linear") {
    state.interpolation = DeltaInterpolation::kLinear;
  } else if (interpolation == "rotation") {
    state.interpolation = DeltaInterpolation::kRotation;
  } else {
    return InvalidArgumentError(
        fmt::format("--interpolation must be linear or rotation, got '{}'", interpolation));
  }
  const MeshTopology& topology = context.topology;
  const int v_count = topology.vertex_count;
  const Selection& selection = context.selection;
  state.whole_mesh = selection.handles.empty() && selection.fixed.empty();
  state.laplacian = context.laplace->matrix;
  if (state.whole_mesh) {
    std::vector<uint8_t> seen(topology.component_count, 0);
    for (int v = 0; v < v_count; ++v) {
      if (!seen[topology.component_of_vertex[v]]) {
        seen[topology.component_of_vertex[v]] = 1;
        state.constrained_vertices.push_back(v);
      }
    }
    state.component_of_vertex = topology.component_of_vertex;
    state.component_count = topology.component_count;
  } else {
    state.constrained_vertices.assign(selection.handles.begin(), selection.handles.end());
    state.handle_count = static_cast<int>(selection.handles.size());
    state.constrained_vertices.insert(state.constrained_vertices.end(), selection.fixed.begin(),
                                      selection.fixed.end());
  }
  std::vector<int> constrained_index(v_count, -1), free_index(v_count, -1);
  for (size_t k = 0; k < state.constrained_vertices.size(); ++k) {
    constrained_index[state.constrained_vertices[k]] = static_cast<int>(k);
  }
  std::vector<uint8_t> free(v_count, 0);
  for (int v = 0; v < v_count; ++v) {
    if (constrained_index[v] < 0) {
      free_index[v] = static_cast<int>(state.free_vertices.size());
      state.free_vertices.push_back(v);
      free[v] = 1;
    }
  }
  std::vector<uint8_t> pinned(v_count, 0);
  for (int v : state.constrained_vertices) pinned[v] = 1;
  DMC_RETURN_IF_ERROR(
      processing::CheckComponentsPinned(topology, free, pinned, "handle or fixed vertex"));
  state.constrained_columns = processing::SelectColumns(
      state.laplacian, constrained_index, static_cast<int>(state.constrained_vertices.size()));
  const SparseMatrixD free_columns = processing::SelectColumns(
      state.laplacian, free_index, static_cast<int>(state.free_vertices.size()));
  state.free_columns_transpose = free_columns.transpose();
  SparseMatrixD normal = state.free_columns_transpose * free_columns;
  if (normal.rows() == 0) normal = SparseMatrixD(Eigen::MatrixXd::Identity(1, 1).sparseView());
  StatusOr<SparseSpdSolver> solver = SparseSpdSolver::Factor(normal);
  if (!solver.ok()) return solver.status().WithContext("morph: the normal matrix");
  return std::unique_ptr<PreparedMethod>(
      new PreparedMorph(std::move(state), std::move(solver).value()));
}

constexpr ParameterSpec kParameters[] = {
    {"from", ParameterType::kInteger, "0", "source frame (t = 0)"},
    {"to", ParameterType::kInteger, "-1", "target frame (t = 1); negative counts from the end"},
    {"frames", ParameterType::kInteger, "11", "output frames, t = 0 .. 1 evenly (>= 2)"},
    {"interpolation", ParameterType::kText, "rotation",
     "delta interpolation: linear, or rotation (lengths linear, directions by Rodrigues)"},
};

}  // namespace

MethodInfo MorphMethod() {
  return {.name = "morph",
          .description =
              "morph between two frames by interpolating differential coordinates "
              "(linear or Rodrigues rotation); partial with a selection",
          .scope = MethodScope::kWholeSequence,
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc

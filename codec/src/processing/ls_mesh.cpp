// ls-mesh: least-squares meshes (Sorkine & Cohen-Or 2004; thesis 3.6). The geometry is rebuilt
// from the connectivity and a few weighted control points alone:
//   min ‖L x‖² + Σ_c ω_c² ‖x_c − p_c‖²,   i.e. (LᵀL + Σ_c ω_c² e_c e_cᵀ) x = Σ_c ω_c² p_c e_c,
// per coordinate. Control points are the selection's handles, at their input positions moved by
// the selection's transform (or FrameConstraints targets); ω_c are the selection's "weights" or
// --weight for all. The factorisation depends only on the operator and the control vertices.
#include <fmt/format.h>

#include "dmc/processing.h"
#include "processing/processing_util.h"

namespace dmc {
namespace {

class PreparedLeastSquaresMesh final : public PreparedMethod {
 public:
  PreparedLeastSquaresMesh(Selection selection, Eigen::Index user_handle_count,
                           std::vector<double> weights, int vertex_count, SparseSpdSolver solver)
      : user_handle_count_(user_handle_count),
        selection_(std::move(selection)),
        weights_(std::move(weights)),
        vertex_count_(vertex_count),
        solver_(std::move(solver)) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints* constraints) const override {
    if (positions.rows() != vertex_count_) {
      return MismatchError(
          fmt::format("frame has {} vertices, the mesh {}", positions.rows(), vertex_count_));
    }
    Eigen::MatrixXd targets = TransformedHandlePositions(selection_, positions);
    if (constraints != nullptr && constraints->handle_positions.size() > 0) {
      if (constraints->handle_positions.rows() != user_handle_count_ ||
          constraints->handle_positions.cols() != 3) {
        return MismatchError(fmt::format("{} control point targets given for {} control points",
                                         constraints->handle_positions.rows(), user_handle_count_));
      }
      targets.topRows(user_handle_count_) = constraints->handle_positions;
    }
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(vertex_count_, 3);
    for (size_t k = 0; k < selection_.handles.size(); ++k) {
      rhs.row(selection_.handles[k]) +=
          weights_[k] * weights_[k] * targets.row(static_cast<Eigen::Index>(k));
    }
    DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd solved, solver_.Solve(rhs));
    FrameOutput output;
    output.positions = processing::ToFrame(solved);
    double error = 0.0;
    for (size_t k = 0; k < selection_.handles.size(); ++k) {
      error = std::max(error, (output.positions.row(selection_.handles[k]) -
                               targets.row(static_cast<Eigen::Index>(k)))
                                  .norm());
    }
    output.measurements.push_back({frame_index, "control_point_error", error});
    output.measurements.push_back({frame_index, "distance_to_input",
                                   (output.positions - positions).rowwise().norm().maxCoeff()});
    return output;
  }

 private:
  Eigen::Index user_handle_count_;  // the selection's handles; isolated vertices follow them
  Selection selection_;
  std::vector<double> weights_;
  int vertex_count_;
  SparseSpdSolver solver_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const double weight, context.parameters.Number("weight"));
  if (!(weight > 0.0)) return InvalidArgumentError("--weight must be > 0");
  const int v_count = context.topology.vertex_count;
  Selection selection = context.selection;
  std::vector<double> weights = selection.handle_weights;
  if (weights.empty()) weights.assign(selection.handles.size(), weight);
  // Isolated vertices are not coupled to anything: they become unit-weight control points at
  // their own (transformed) positions, so the system stays definite.
  const std::vector<uint8_t> handle_mask = processing::MaskOf(selection.handles, v_count);
  for (int v = 0; v < v_count; ++v) {
    if (context.topology.degree(v) == 0 && !handle_mask[v]) {
      selection.handles.push_back(v);
      weights.push_back(1.0);
    }
  }
  DMC_RETURN_IF_ERROR(processing::CheckComponentsPinned(
      context.topology, std::vector<uint8_t>(v_count, 1),
      processing::MaskOf(selection.handles, v_count), "control point (handle)"));
  const SparseMatrixD& laplacian = context.laplace->matrix;
  SparseMatrixD normal = SparseMatrixD(laplacian.transpose()) * laplacian;
  std::vector<Eigen::Triplet<double>> diagonal;
  for (size_t k = 0; k < selection.handles.size(); ++k) {
    diagonal.emplace_back(selection.handles[k], selection.handles[k], weights[k] * weights[k]);
  }
  SparseMatrixD control(v_count, v_count);
  control.setFromTriplets(diagonal.begin(), diagonal.end());
  normal += control;
  StatusOr<SparseSpdSolver> solver = SparseSpdSolver::Factor(normal);
  if (!solver.ok()) return solver.status().WithContext("ls-mesh: the normal matrix");
  return std::unique_ptr<PreparedMethod>(new PreparedLeastSquaresMesh(
      selection, static_cast<Eigen::Index>(context.selection.handles.size()), std::move(weights),
      v_count, std::move(solver).value()));
}

constexpr ParameterSpec kParameters[] = {
    {"weight", ParameterType::kNumber, "1",
     "control point weight omega (> 0) when the selection has no \"weights\""},
};

}  // namespace

MethodInfo LeastSquaresMeshMethod() {
  return {.name = "ls-mesh",
          .description =
              "least-squares mesh: geometry from connectivity and weighted control "
              "points (the selection's handles)",
          .needs_selection = true,
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc

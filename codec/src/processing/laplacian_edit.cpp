// laplacian-edit: Laplacian surface editing (thesis 3.4; Alexa 2003, Sorkine et al. 2004).
//
// Vertices are handles H (moved by the selection's transform), fixed F (kept) and free U (the
// rest). The edited positions keep the input's differential coordinates δ = L·x as well as
// possible, per coordinate:
//   hard:  min ‖L_U x_U − (δ − L_C x_C)‖² + w_a²‖x_A − x̄_A‖²   (constrained columns C = H ∪ F
//          eliminated, thesis 3.4: the |V|×|U| system L′x′ = d′ solved in the least-squares
//          sense through the normal equations L_Uᵀ L_U),
//   soft:  min ‖L x − δ‖² + λ²‖x_C − c‖² + w_a²‖x_A − x̄_A‖²   (normal equations LᵀL + λ²P_CᵀP_C),
// with optional anchor rows A (free vertices softly kept at their input positions). As λ → ∞ the
// soft solution converges to the hard one (tested). Both factorisations depend only on the
// operator and the vertex roles, so every frame and every new handle target reuses them.
#include <fmt/format.h>

#include <algorithm>

#include "dmc/processing.h"
#include "processing/processing_util.h"

namespace dmc {
namespace {

constexpr ParameterSpec kParameters[] = {
    {"constraints", ParameterType::kText, "hard",
     "hard (constrained unknowns eliminated) or soft (weighted rows, see --weight)"},
    {"weight", ParameterType::kNumber, "100", "soft constraint weight lambda (> 0)"},
    {"anchor-weight", ParameterType::kNumber, "1",
     "weight of the selection's anchor rows x'_a = x_a (> 0)"},
};

class PreparedLaplacianEdit final : public PreparedMethod {
 public:
  PreparedLaplacianEdit(SparseMatrixD laplacian, Selection selection, bool hard,
                        double constraint_weight, double anchor_weight,
                        std::vector<int> free_vertices, SparseMatrixD free_columns_transpose,
                        SparseMatrixD constrained_columns, std::vector<int> constrained_vertices,
                        SparseSpdSolver solver)
      : laplacian_(std::move(laplacian)),
        selection_(std::move(selection)),
        hard_(hard),
        constraint_weight_(constraint_weight),
        anchor_weight_(anchor_weight),
        free_vertices_(std::move(free_vertices)),
        free_columns_transpose_(std::move(free_columns_transpose)),
        constrained_columns_(std::move(constrained_columns)),
        constrained_vertices_(std::move(constrained_vertices)),
        solver_(std::move(solver)) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints* constraints) const override {
    const Eigen::Index v_count = laplacian_.rows();
    if (positions.rows() != v_count) {
      return MismatchError(
          fmt::format("frame has {} vertices, the operator {}", positions.rows(), v_count));
    }
    Eigen::MatrixXd handle_targets;
    if (constraints != nullptr && constraints->handle_positions.size() > 0) {
      if (constraints->handle_positions.rows() !=
              static_cast<Eigen::Index>(selection_.handles.size()) ||
          constraints->handle_positions.cols() != 3) {
        return MismatchError(fmt::format("{} handle targets given for {} handles",
                                         constraints->handle_positions.rows(),
                                         selection_.handles.size()));
      }
      handle_targets = constraints->handle_positions;
    } else {
      handle_targets = TransformedHandlePositions(selection_, positions);
    }
    // Targets of the constrained vertices, in constrained_vertices_ order (handles then fixed).
    Eigen::MatrixXd targets(constrained_vertices_.size(), 3);
    for (size_t k = 0; k < selection_.handles.size(); ++k) {
      targets.row(static_cast<Eigen::Index>(k)) = handle_targets.row(static_cast<Eigen::Index>(k));
    }
    for (size_t k = 0; k < selection_.fixed.size(); ++k) {
      targets.row(static_cast<Eigen::Index>(selection_.handles.size() + k)) =
          positions.row(selection_.fixed[k]);
    }
    const Eigen::MatrixXd input = processing::ToDense(positions);
    const Eigen::MatrixXd delta = laplacian_ * input;

    FrameOutput output;
    output.positions = positions;
    if (hard_) {
      if (!free_vertices_.empty()) {
        Eigen::MatrixXd rhs = free_columns_transpose_ * (delta - constrained_columns_ * targets);
        AddAnchorTerms(input, rhs, /*use_free_index=*/true);
        DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd solved, solver_.Solve(rhs));
        for (size_t k = 0; k < free_vertices_.size(); ++k) {
          output.positions.row(free_vertices_[k]) = solved.row(static_cast<Eigen::Index>(k));
        }
      }
      for (size_t k = 0; k < constrained_vertices_.size(); ++k) {
        output.positions.row(constrained_vertices_[k]) = targets.row(static_cast<Eigen::Index>(k));
      }
    } else {
      Eigen::MatrixXd rhs = laplacian_.transpose() * delta;
      const double lambda_squared = constraint_weight_ * constraint_weight_;
      for (size_t k = 0; k < constrained_vertices_.size(); ++k) {
        rhs.row(constrained_vertices_[k]) +=
            lambda_squared * targets.row(static_cast<Eigen::Index>(k));
      }
      AddAnchorTerms(input, rhs, /*use_free_index=*/false);
      DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd solved, solver_.Solve(rhs));
      output.positions = processing::ToFrame(solved);
    }
    double handle_error = 0.0;
    for (size_t k = 0; k < constrained_vertices_.size(); ++k) {
      handle_error = std::max(handle_error, (output.positions.row(constrained_vertices_[k]) -
                                             targets.row(static_cast<Eigen::Index>(k)))
                                                .norm());
    }
    output.measurements.push_back({frame_index, "constraint_error", handle_error});
    output.measurements.push_back({frame_index, "max_displacement",
                                   (output.positions - positions).rowwise().norm().maxCoeff()});
    return output;
  }

 private:
  // rhs += w_a²·x̄_a for every anchor, in free-vertex numbering (hard) or vertex numbering (soft).
  void AddAnchorTerms(const Eigen::MatrixXd& input, Eigen::MatrixXd& rhs,
                      bool use_free_index) const {
    const double weight_squared = anchor_weight_ * anchor_weight_;
    for (int32_t anchor : selection_.anchors) {
      Eigen::Index row = anchor;
      if (use_free_index) {
        row = std::lower_bound(free_vertices_.begin(), free_vertices_.end(), anchor) -
              free_vertices_.begin();
      }
      rhs.row(row) += weight_squared * input.row(anchor);
    }
  }

  SparseMatrixD laplacian_;
  Selection selection_;
  bool hard_;
  double constraint_weight_;
  double anchor_weight_;
  std::vector<int> free_vertices_;         // U, ascending
  SparseMatrixD free_columns_transpose_;   // L_Uᵀ (hard only)
  SparseMatrixD constrained_columns_;      // L_C, columns in constrained_vertices_ order
  std::vector<int> constrained_vertices_;  // handles, then fixed
  SparseSpdSolver solver_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const std::string mode, context.parameters.Text("constraints"));
  DMC_ASSIGN_OR_RETURN(const double weight, context.parameters.Number("weight"));
  DMC_ASSIGN_OR_RETURN(const double anchor_weight, context.parameters.Number("anchor-weight"));
  if (mode != "hard" && mode != "soft") {
    return InvalidArgumentError(fmt::format("--constraints must be hard or soft, got '{}'", mode));
  }
  if (!(weight > 0.0)) return InvalidArgumentError("--weight must be > 0");
  if (!(anchor_weight > 0.0)) return InvalidArgumentError("--anchor-weight must be > 0");
  const bool hard = mode == "hard";
  const int v_count = context.topology.vertex_count;
  // Isolated vertices have no differential coordinate to keep: they stay where they are.
  Selection selection = context.selection;
  const std::vector<uint8_t> handle_mask = processing::MaskOf(selection.handles, v_count);
  const std::vector<uint8_t> fixed_mask = processing::MaskOf(selection.fixed, v_count);
  for (int v = 0; v < v_count; ++v) {
    if (context.topology.degree(v) == 0 && !handle_mask[v] && !fixed_mask[v]) {
      selection.fixed.push_back(v);
    }
  }
  std::sort(selection.fixed.begin(), selection.fixed.end());
  std::erase_if(selection.anchors, [&](int32_t v) { return context.topology.degree(v) == 0; });
  const SparseMatrixD& laplacian = context.laplace->matrix;

  std::vector<int> constrained_vertices(selection.handles.begin(), selection.handles.end());
  constrained_vertices.insert(constrained_vertices.end(), selection.fixed.begin(),
                              selection.fixed.end());
  std::vector<int> constrained_index(v_count, -1), free_index(v_count, -1);
  for (size_t k = 0; k < constrained_vertices.size(); ++k) {
    constrained_index[constrained_vertices[k]] = static_cast<int>(k);
  }
  std::vector<int> free_vertices;
  for (int v = 0; v < v_count; ++v) {
    if (constrained_index[v] < 0) {
      free_index[v] = static_cast<int>(free_vertices.size());
      free_vertices.push_back(v);
    }
  }
  // Each component with an unknown needs something that pins its translation.
  std::vector<uint8_t> pinned = processing::MaskOf(selection.anchors, v_count);
  for (int v : constrained_vertices) pinned[v] = 1;
  std::vector<uint8_t> unknown(v_count, 0);
  for (int v = 0; v < v_count; ++v) unknown[v] = hard ? constrained_index[v] < 0 : 1;
  DMC_RETURN_IF_ERROR(processing::CheckComponentsPinned(context.topology, unknown, pinned,
                                                        "handle, fixed vertex or anchor"));

  SparseMatrixD constrained_columns = processing::SelectColumns(
      laplacian, constrained_index, static_cast<int>(constrained_vertices.size()));
  SparseMatrixD free_columns_transpose;
  SparseMatrixD normal;
  std::vector<int> anchor_rows;
  if (hard) {
    const SparseMatrixD free_columns =
        processing::SelectColumns(laplacian, free_index, static_cast<int>(free_vertices.size()));
    free_columns_transpose = free_columns.transpose();
    normal = free_columns_transpose * free_columns;
    for (int32_t anchor : selection.anchors) anchor_rows.push_back(free_index[anchor]);
  } else {
    normal = SparseMatrixD(laplacian.transpose()) * laplacian;
    processing::AddToDiagonal(normal, constrained_vertices, weight * weight);
    anchor_rows.assign(selection.anchors.begin(), selection.anchors.end());
  }
  processing::AddToDiagonal(normal, anchor_rows, anchor_weight * anchor_weight);
  // An all-constrained hard edit has no unknowns; a 1×1 identity keeps the solver well defined.
  if (normal.rows() == 0) normal = SparseMatrixD(Eigen::MatrixXd::Identity(1, 1).sparseView());
  StatusOr<SparseSpdSolver> solver = SparseSpdSolver::Factor(normal);
  if (!solver.ok()) {
    return solver.status().WithContext(
        fmt::format("laplacian-edit ({} constraints): the normal matrix", mode));
  }
  return std::unique_ptr<PreparedMethod>(new PreparedLaplacianEdit(
      laplacian, selection, hard, weight, anchor_weight, std::move(free_vertices),
      std::move(free_columns_transpose), std::move(constrained_columns),
      std::move(constrained_vertices), std::move(solver).value()));
}

}  // namespace

MethodInfo LaplacianEditMethod() {
  return {
      .name = "laplacian-edit",
      .description =
          "Laplacian surface editing: handles moved by the selection's transform, "
          "fixed vertices kept, free vertices keep their differential coordinates",
      .scope = MethodScope::kPerFrame,
      .needs_operator = true,
      .needs_selection = true,
      .vertex_scalar = {},
      .parameters = kParameters,
      .precompute = Precompute,
  };
}

}  // namespace dmc

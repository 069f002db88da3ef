// poisson-fit: gradient-domain fitting of a per-vertex field with the restricted B-spline
// elements and their octree multigrid (Chuang et al. 2009, §5.2–5.3, dmc/bspline.h).
//
// The field f (the three coordinate functions, or one of them) is fitted by the element function
// u minimising the screened Poisson energy
//     ∫ |∇_M u − s·∇_M f|² + α ∫ (u − f)²,
// i.e. (−L + αD) η = ψ(s·∇f) + α γ(f): s = 1 with a small α smooths f at the resolution of the
// octree (gradient-domain fitting of noisy samples), s > 1 exaggerates its detail, α large is
// the plain L² projection. The operator and the multigrid are built once on the reference frame;
// each frame's field is fitted on that surface with `cycles` W-cycles. Output: the fitted field
// (positions, or the chosen coordinate replaced), vertex scalar "fit_residual" = |u − f| per
// vertex, measurements rms_change (relative to the bounding-box diagonal) and relative_residual.
#include <fmt/format.h>

#include <cmath>

#include "dmc/bspline.h"
#include "dmc/processing.h"

namespace dmc {
namespace {

class PreparedPoissonFit final : public PreparedMethod {
 public:
  PreparedPoissonFit(BsplineOperator op, BsplineMultigrid multigrid, int axis, double alpha,
                     double gradient_scale, int cycles)
      : PreparedMethod("fit_residual"),
        op_(std::move(op)),
        multigrid_(std::move(multigrid)),
        axis_(axis),
        alpha_(alpha),
        gradient_scale_(gradient_scale),
        cycles_(cycles) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints*) const override {
    if (positions.rows() != op_.positions.rows()) {
      return MismatchError(fmt::format("frame has {} vertices, the operator's mesh {}",
                                       positions.rows(), op_.positions.rows()));
    }
    const Eigen::MatrixXd field =
        axis_ < 0 ? Eigen::MatrixXd(positions) : Eigen::MatrixXd(positions.col(axis_));
    DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd values, IntegrateValueLoad(op_, field));
    DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd gradients,
                         IntegrateGradientLoad(op_, field, gradient_scale_));
    const Eigen::MatrixXd rhs = gradients + alpha_ * values;
    MultigridOptions options;
    options.cycle = MultigridCycle::kW;
    options.max_cycles = cycles_;
    options.relative_tolerance = 0.0;  // run exactly `cycles` cycles
    Eigen::MatrixXd fitted(field.rows(), field.cols());
    double residual = 0.0, norm = 0.0;
    for (Eigen::Index c = 0; c < field.cols(); ++c) {
      Eigen::VectorXd coefficients = Eigen::VectorXd::Zero(op_.dimension());
      DMC_ASSIGN_OR_RETURN(const MultigridReport report,
                           multigrid_.Solve(rhs.col(c), coefficients, options));
      residual += report.final_residual * report.final_residual;
      norm += rhs.col(c).squaredNorm();
      fitted.col(c) = op_.evaluation * coefficients;
    }
    FrameOutput output;
    output.positions = positions;
    if (axis_ < 0) {
      output.positions = fitted;
    } else {
      output.positions.col(axis_) = fitted.col(0);
    }
    output.vertex_scalar = (fitted - field).rowwise().norm();
    const Eigen::Vector3d low = positions.colwise().minCoeff(),
                          high = positions.colwise().maxCoeff();
    const double diagonal = (high - low).norm();
    const double rms =
        std::sqrt((fitted - field).squaredNorm() / static_cast<double>(field.rows()));
    output.measurements.push_back(
        {frame_index, "rms_change", diagonal > 0.0 ? rms / diagonal : 0.0});
    output.measurements.push_back(
        {frame_index, "relative_residual", norm > 0.0 ? std::sqrt(residual / norm) : 0.0});
    return output;
  }

 private:
  BsplineOperator op_;
  BsplineMultigrid multigrid_;
  int axis_;  // −1: all three coordinates
  double alpha_;
  double gradient_scale_;
  int cycles_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const int depth, context.parameters.Integer("depth"));
  DMC_ASSIGN_OR_RETURN(const double alpha, context.parameters.Number("alpha"));
  DMC_ASSIGN_OR_RETURN(const double gradient_scale, context.parameters.Number("gradient-scale"));
  DMC_ASSIGN_OR_RETURN(const int cycles, context.parameters.Integer("cycles"));
  DMC_ASSIGN_OR_RETURN(const std::string field, context.parameters.Text("field"));
  if (depth < 1 || depth > 10) {
    return InvalidArgumentError(fmt::format("--depth must be in [1, 10], got {}", depth));
  }
  if (!(alpha > 0.0) || !std::isfinite(alpha)) {
    return InvalidArgumentError(fmt::format("--alpha must be a finite value > 0, got {}", alpha));
  }
  if (!std::isfinite(gradient_scale)) {
    return InvalidArgumentError("--gradient-scale must be finite");
  }
  if (cycles < 1) return InvalidArgumentError(fmt::format("--cycles must be >= 1, got {}", cycles));
  int axis = -1;
  if (field == "x" || field == "y" || field == "z") {
    axis = field[0] - 'x';
  } else if (field != "positions") {
    return InvalidArgumentError(
        fmt::format("--field must be positions, x, y or z, got '{}'", field));
  }
  BsplineOptions options;
  options.depth = depth;
  options.coarsest_depth = std::min(depth, 2);
  DMC_ASSIGN_OR_RETURN(BsplineOperator op, BuildBsplineOperator(context.sequence.triangles(),
                                                                context.reference_frame, options));
  DMC_ASSIGN_OR_RETURN(BsplineMultigrid multigrid, BsplineMultigrid::Create(op, 1.0, alpha));
  return std::unique_ptr<PreparedMethod>(new PreparedPoissonFit(
      std::move(op), std::move(multigrid), axis, alpha, gradient_scale, cycles));
}

constexpr ParameterSpec kParameters[] = {
    {"depth", ParameterType::kInteger, "6", "octree depth of the B-spline elements"},
    {"alpha", ParameterType::kNumber, "0.05",
     "weight of the values against the gradients (screening; large: L2 projection)"},
    {"gradient-scale", ParameterType::kNumber, "1",
     "factor on the target gradients (> 1 exaggerates detail)"},
    {"cycles", ParameterType::kInteger, "10", "multigrid W-cycles per field channel"},
    {"field", ParameterType::kText, "positions", "field to fit: positions, x, y or z"},
};

}  // namespace

MethodInfo BsplinePoissonFitMethod() {
  return {.name = "poisson-fit",
          .description =
              "gradient-domain fit of the coordinates (or one of them) with B-spline octree "
              "elements and multigrid: screened Poisson, optional gradient scaling",
          .needs_operator = false,
          .vertex_scalar = "fit_residual",
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc

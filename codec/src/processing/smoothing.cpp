// Smoothing (thesis 3.2): explicit iterative smoothing, Taubin's λ|μ smoothing and implicit
// fairing, all with one operator for every frame (3.2.5).
//
//   smooth-explicit  x ← x + λ′·L·x, `iterations` times (λ > 1 flips curvature: 3.2.2)
//   smooth-taubin    x ← x + λ′·L·x, then x ← x + μ′·L·x, per iteration, with μ from the pass-band
//                    frequency k_PB = 1/λ + 1/μ > 0 (Taubin 1995; 3.2.3), so μ < −λ < 0
//   smooth-implicit  (I − λ′·L)·x_{n+1} = x_n, `iterations` times (Desbrun et al. 1999; 3.2.4),
//                    one factorisation for all iterations and frames
//
// Implicit fairing: λ′ = λ / s_L, s_L the mean |L_ii| for operators without unit row sum
// (kirchhoff, cotan-area, cotan-sym) and 1 otherwise, the thesis's scaling (6.3) that makes one
// λ comparable across operators. Explicit and Taubin steps: λ′ = λ / (ρ̂/2), ρ̂ the Gershgorin
// bound on L's spectral radius (2 for unit-sum operators with non-negative weights, so their λ′
// is λ as before): the mean |L_ii| is no stability bound (cotan-sym and cotan-area diverged at
// the default λ = 0.5 with λ′·ρ = 5.8 and 14.5 on real meshes), while with this scale λ ≤ 1 is
// always stable. A λ (or Taubin pair) whose step times the estimated spectral radius leaves the
// stable range is refused, naming the largest stable λ. λ′ is the measurement "effective_lambda".
#include <fmt/format.h>

#include <Eigen/SparseLU>
#include <cmath>
#include <variant>

#include "dmc/processing.h"
#include "processing/processing_util.h"

namespace dmc {
namespace {

// Signed volume enclosed by a (closed, consistently oriented) triangle mesh; a shrinkage measure.
double SignedVolume(const Triangles& triangles, const FramePositionsD& positions) {
  double volume = 0.0;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const Eigen::Vector3d a = positions.row(triangles(t, 0)).transpose();
    const Eigen::Vector3d b = positions.row(triangles(t, 1)).transpose();
    const Eigen::Vector3d c = positions.row(triangles(t, 2)).transpose();
    volume += a.dot(b.cross(c));
  }
  return volume / 6.0;
}

void AddVolumeMeasurement(const Triangles& triangles, const FramePositionsD& before,
                          FrameOutput& output, int frame_index) {
  const double volume = SignedVolume(triangles, before);
  if (std::abs(volume) > 0.0) {
    output.measurements.push_back(
        {frame_index, "volume_ratio", SignedVolume(triangles, output.positions) / volume});
  }
}

// ---- explicit and Taubin: a list of steps x ← x + s·L·x per iteration.

class PreparedExplicitSmoothing final : public PreparedMethod {
 public:
  PreparedExplicitSmoothing(SparseMatrixD laplacian, Triangles triangles, std::vector<double> steps,
                            int iterations)
      : laplacian_(std::move(laplacian)),
        triangles_(std::move(triangles)),
        steps_(std::move(steps)),
        iterations_(iterations) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints*) const override {
    if (positions.rows() != laplacian_.rows()) {
      return MismatchError(fmt::format("frame has {} vertices, the operator {}", positions.rows(),
                                       laplacian_.rows()));
    }
    Eigen::MatrixXd x = processing::ToDense(positions);
    for (int iteration = 0; iteration < iterations_; ++iteration) {
      for (double step : steps_) x += step * (laplacian_ * x);
    }
    FrameOutput output;
    output.positions = processing::ToFrame(x);
    output.measurements.push_back({frame_index, "effective_lambda", steps_.front()});
    if (steps_.size() > 1) {
      output.measurements.push_back({frame_index, "effective_mu", steps_.back()});
    }
    AddVolumeMeasurement(triangles_, positions, output, frame_index);
    return output;
  }

 private:
  SparseMatrixD laplacian_;
  Triangles triangles_;
  std::vector<double> steps_;
  int iterations_;
};

Status CheckIterations(int iterations) {
  if (iterations < 0 || iterations > 1000000) {
    return InvalidArgumentError("--iterations must be in [0, 1000000]");
  }
  return Status::Ok();
}

// Half the Gershgorin bound: the scale of explicit steps (see the top of the file).
double ExplicitStepScale(const SparseMatrixD& laplacian) {
  const double bound = processing::SpectralRadiusBound(laplacian);
  return bound > 0.0 ? bound / 2.0 : 1.0;
}

// kInvalidArgument when the steps amplify L's highest frequency, |Π (1 − s·ρ)| > 1 with ρ the
// estimated spectral radius: iterating would diverge. `hint` says what to change.
Status CheckStable(std::string_view method, double lambda, const std::vector<double>& steps,
                   const SparseMatrixD& laplacian, const std::string& hint_format) {
  const double radius = processing::SpectralRadiusEstimate(laplacian);
  double gain = 1.0;
  for (double step : steps) gain *= 1.0 - step * radius;
  if (std::abs(gain) > 1.0 + 1e-9) {
    return InvalidArgumentError(fmt::format(
        "{}: lambda {:g} diverges with this operator: the effective step {:g} times "
        "its spectral radius {:.4g} amplifies the highest frequency {:.3g}-fold per "
        "iteration; {}",
        method, lambda, steps.front(), radius, std::abs(gain),
        fmt::format(fmt::runtime(hint_format), 2.0 * lambda / (steps.front() * radius))));
  }
  return Status::Ok();
}

StatusOr<std::unique_ptr<PreparedMethod>> PrecomputeExplicit(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const double lambda, context.parameters.Number("lambda"));
  DMC_ASSIGN_OR_RETURN(const int iterations, context.parameters.Integer("iterations"));
  DMC_RETURN_IF_ERROR(CheckIterations(iterations));
  const double scale = ExplicitStepScale(context.laplace->matrix);
  // |1 − λ′ρ| ≤ 1 ⇔ λ′ρ ≤ 2.
  DMC_RETURN_IF_ERROR(CheckStable("smooth-explicit", lambda, {lambda / scale},
                                  context.laplace->matrix, "use lambda <= {:.4g}"));
  return std::unique_ptr<PreparedMethod>(new PreparedExplicitSmoothing(
      context.laplace->matrix, context.sequence.triangles(), {lambda / scale}, iterations));
}

StatusOr<std::unique_ptr<PreparedMethod>> PrecomputeTaubin(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const double lambda, context.parameters.Number("lambda"));
  DMC_ASSIGN_OR_RETURN(double mu, context.parameters.Number("mu"));
  DMC_ASSIGN_OR_RETURN(const double pass_band, context.parameters.Number("pass-band"));
  DMC_ASSIGN_OR_RETURN(const int iterations, context.parameters.Integer("iterations"));
  DMC_RETURN_IF_ERROR(CheckIterations(iterations));
  if (!(lambda > 0.0)) return InvalidArgumentError("--lambda must be > 0");
  if (mu == 0.0) {
    // k_PB = 1/λ + 1/μ  ⇒  μ = 1 / (k_PB − 1/λ); k_PB < 1/λ keeps μ negative.
    if (!(pass_band > 0.0) || !(pass_band < 1.0 / lambda)) {
      return InvalidArgumentError(fmt::format(
          "--pass-band must lie in (0, 1/lambda) = (0, {:g}), got {:g}", 1.0 / lambda, pass_band));
    }
    mu = 1.0 / (pass_band - 1.0 / lambda);
  }
  if (!(mu < -lambda)) {
    return InvalidArgumentError(
        fmt::format("Taubin smoothing needs mu < -lambda (got lambda {:g}, mu {:g})", lambda, mu));
  }
  const double scale = ExplicitStepScale(context.laplace->matrix);
  DMC_RETURN_IF_ERROR(
      CheckStable("smooth-taubin", lambda, {lambda / scale, mu / scale}, context.laplace->matrix,
                  "use a smaller lambda (lambda alone is stable up to {:.4g}) or a smaller |mu|"));
  return std::unique_ptr<PreparedMethod>(
      new PreparedExplicitSmoothing(context.laplace->matrix, context.sequence.triangles(),
                                    {lambda / scale, mu / scale}, iterations));
}

// ---- implicit fairing

class PreparedImplicitSmoothing final : public PreparedMethod {
 public:
  using LuSolver = Eigen::SparseLU<SparseMatrixD, Eigen::COLAMDOrdering<int>>;

  PreparedImplicitSmoothing(Triangles triangles, int iterations, double step,
                            std::variant<SparseSpdSolver, std::unique_ptr<LuSolver>> solver)
      : triangles_(std::move(triangles)),
        iterations_(iterations),
        step_(step),
        solver_(std::move(solver)) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints*) const override {
    Eigen::MatrixXd x = processing::ToDense(positions);
    for (int iteration = 0; iteration < iterations_; ++iteration) {
      if (const auto* spd = std::get_if<SparseSpdSolver>(&solver_)) {
        if (spd->size() != x.rows()) return MismatchError("frame size differs from the operator's");
        DMC_ASSIGN_OR_RETURN(x, spd->Solve(x));
      } else {
        const LuSolver& lu = *std::get<std::unique_ptr<LuSolver>>(solver_);
        if (lu.rows() != x.rows()) return MismatchError("frame size differs from the operator's");
        Eigen::MatrixXd next = lu.solve(x);
        if (lu.info() != Eigen::Success || !next.allFinite()) {
          return NumericalFailureError("implicit fairing: the LU solve failed");
        }
        x = std::move(next);
      }
    }
    FrameOutput output;
    output.positions = processing::ToFrame(x);
    output.measurements.push_back({frame_index, "effective_lambda", step_});
    AddVolumeMeasurement(triangles_, positions, output, frame_index);
    return output;
  }

 private:
  Triangles triangles_;
  int iterations_;
  double step_;
  std::variant<SparseSpdSolver, std::unique_ptr<LuSolver>> solver_;
};

StatusOr<std::unique_ptr<PreparedMethod>> PrecomputeImplicit(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const double lambda, context.parameters.Number("lambda"));
  DMC_ASSIGN_OR_RETURN(const int iterations, context.parameters.Integer("iterations"));
  DMC_RETURN_IF_ERROR(CheckIterations(iterations));
  if (!(lambda >= 0.0)) return InvalidArgumentError("--lambda must be >= 0");
  const LaplaceOperator& laplace = *context.laplace;
  const double step = lambda / processing::StepScale(laplace);
  const Eigen::Index n = laplace.matrix.rows();
  SparseMatrixD identity(n, n);
  identity.setIdentity();
  const SparseMatrixD system = identity - step * laplace.matrix;
  // A symmetric operator with non-negative weights makes I − λ′L symmetric positive definite
  // (Cholesky); otherwise (non-symmetric rows, or negative cotangent weights) use sparse LU.
  if (laplace.symmetric) {
    StatusOr<SparseSpdSolver> spd = SparseSpdSolver::Factor(system);
    if (spd.ok()) {
      return std::unique_ptr<PreparedMethod>(new PreparedImplicitSmoothing(
          context.sequence.triangles(), iterations, step, std::move(spd).value()));
    }
  }
  auto lu = std::make_unique<PreparedImplicitSmoothing::LuSolver>();
  lu->compute(system);
  if (lu->info() != Eigen::Success) {
    return NumericalFailureError(
        fmt::format("implicit fairing: I - {:g} L is singular ({})", step, lu->lastErrorMessage()));
  }
  return std::unique_ptr<PreparedMethod>(
      new PreparedImplicitSmoothing(context.sequence.triangles(), iterations, step, std::move(lu)));
}

constexpr ParameterSpec kExplicitParameters[] = {
    {"lambda", ParameterType::kNumber, "0.5",
     "step lambda of x' = x + lambda' L x, lambda' = 2 lambda / (Gershgorin bound of L's "
     "spectral radius): lambda itself for unit-sum operators; > 1 flips curvature; a lambda that "
     "would diverge is refused"},
    {"iterations", ParameterType::kInteger, "10", "number of steps"},
};
constexpr ParameterSpec kTaubinParameters[] = {
    {"lambda", ParameterType::kNumber, "0.5",
     "shrinking step lambda > 0 (scaled as smooth-explicit's; a pair that would diverge is "
     "refused)"},
    {"mu", ParameterType::kNumber, "0",
     "growing step mu < -lambda; 0 derives it from --pass-band: mu = 1 / (k_PB - 1/lambda)"},
    {"pass-band", ParameterType::kNumber, "0.1",
     "pass-band frequency k_PB = 1/lambda + 1/mu (Taubin: 0.01 .. 0.1)"},
    {"iterations", ParameterType::kInteger, "10", "number of lambda|mu iterations"},
};
constexpr ParameterSpec kImplicitParameters[] = {
    {"lambda", ParameterType::kNumber, "1",
     "lambda dt of (I - lambda dt L) x' = x (scaled by 1/mean|L_ii| for non-unit-sum operators)"},
    {"iterations", ParameterType::kInteger, "1", "number of implicit steps"},
};

}  // namespace

MethodInfo SmoothExplicitMethod() {
  return {.name = "smooth-explicit",
          .description = "explicit Laplacian smoothing x' = x + lambda L x, iterated",
          .parameters = kExplicitParameters,
          .precompute = PrecomputeExplicit};
}

MethodInfo SmoothTaubinMethod() {
  return {.name = "smooth-taubin",
          .description = "Taubin's lambda|mu smoothing (no shrinkage), mu from the pass-band",
          .parameters = kTaubinParameters,
          .precompute = PrecomputeTaubin};
}

MethodInfo SmoothImplicitMethod() {
  return {.name = "smooth-implicit",
          .description = "implicit fairing (I - lambda dt L) x' = x, one factorisation",
          .parameters = kImplicitParameters,
          .precompute = PrecomputeImplicit};
}

}  // namespace dmc

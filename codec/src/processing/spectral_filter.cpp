// spectral-filter: manifold-harmonics filtering (Vallet & Lévy 2008; thesis 3.2.1) with the
// first k eigenvectors of a symmetric operator, computed once with Spectra's shift-invert
// Lanczos solver.
//
// −L is symmetric positive semidefinite for kirchhoff and for positive-weight cotan-sym / ddl.
// With a mass matrix M (cotan-sym) the basis is M-orthonormal: the generalised problem
// −L e = λ M e is solved as the standard one for A = M^{-1/2}(−L)M^{-1/2}, e = M^{-1/2} ẽ.
// Filters on the coordinates f (V×3), with c = Ẽᵀ M^{1/2} f the first k spectral coefficients:
//   lowpass   f̂ = M^{-1/2} Ẽ c                      (reconstruction from k harmonics)
//   enhance   f̂ = f + (gain − 1)·(f − lowpass(f))   (detail above the k-th frequency amplified)
// Measurements: eigenvalue range and the relative change ‖f̂ − f‖_F / ‖f‖_F.
#include <Spectra/MatOp/SparseSymShiftSolve.h>
#include <Spectra/SymEigsShiftSolver.h>
#include <fmt/format.h>

#include <cmath>

#include "dmc/processing.h"
#include "processing/processing_util.h"

namespace dmc {
namespace {

class PreparedSpectralFilter final : public PreparedMethod {
 public:
  PreparedSpectralFilter(Eigen::MatrixXd basis, Eigen::VectorXd sqrt_mass,
                         Eigen::VectorXd eigenvalues, bool enhance, double gain)
      : basis_(std::move(basis)),
        sqrt_mass_(std::move(sqrt_mass)),
        eigenvalues_(std::move(eigenvalues)),
        enhance_(enhance),
        gain_(gain) {}

  StatusOr<FrameOutput> Apply(const FramePositionsD& positions, int frame_index,
                              const FrameConstraints*) const override {
    if (positions.rows() != basis_.rows()) {
      return MismatchError(
          fmt::format("frame has {} vertices, the basis {}", positions.rows(), basis_.rows()));
    }
    const Eigen::MatrixXd f = processing::ToDense(positions);
    const Eigen::MatrixXd coefficients = basis_.transpose() * (sqrt_mass_.asDiagonal() * f);
    const Eigen::MatrixXd low = sqrt_mass_.cwiseInverse().asDiagonal() * (basis_ * coefficients);
    const Eigen::MatrixXd filtered =
        enhance_ ? Eigen::MatrixXd(f + (gain_ - 1.0) * (f - low)) : low;
    FrameOutput output;
    output.positions = processing::ToFrame(filtered);
    const double norm = f.norm();
    output.measurements.push_back(
        {frame_index, "relative_change", norm > 0.0 ? (filtered - f).norm() / norm : 0.0});
    output.measurements.push_back({frame_index, "eigenvalue_min", eigenvalues_.minCoeff()});
    output.measurements.push_back({frame_index, "eigenvalue_max", eigenvalues_.maxCoeff()});
    return output;
  }

 private:
  Eigen::MatrixXd basis_;      // V×k, orthonormal columns (of the mass-symmetrised problem)
  Eigen::VectorXd sqrt_mass_;  // M^{1/2} diagonal (ones without a mass matrix)
  Eigen::VectorXd eigenvalues_;
  bool enhance_;
  double gain_;
};

StatusOr<std::unique_ptr<PreparedMethod>> Precompute(const ProcessingContext& context) {
  DMC_ASSIGN_OR_RETURN(const int k, context.parameters.Integer("k"));
  DMC_ASSIGN_OR_RETURN(const std::string filter, context.parameters.Text("filter"));
  DMC_ASSIGN_OR_RETURN(const double gain, context.parameters.Number("gain"));
  const LaplaceOperator& laplace = *context.laplace;
  const int v_count = static_cast<int>(laplace.matrix.rows());
  if (!laplace.symmetric) {
    return InvalidArgumentError(fmt::format(
        "spectral-filter needs a symmetric operator (kirchhoff, cotan-sym, ddl); {} is not",
        laplace.name));
  }
  if (filter != "lowpass" && filter != "enhance") {
    return InvalidArgumentError(
        fmt::format("--filter must be lowpass or enhance, got '{}'", filter));
  }
  if (k < 1 || k >= v_count) {
    return InvalidArgumentError(
        fmt::format("--k must be in [1, {}) for {} vertices", v_count, v_count));
  }
  Eigen::VectorXd sqrt_mass = Eigen::VectorXd::Ones(v_count);
  if (laplace.mass.size() == v_count && (laplace.mass.array() > 0.0).all()) {
    sqrt_mass = laplace.mass.cwiseSqrt();
  }
  // A = M^{-1/2} (−L) M^{-1/2}: symmetric positive semidefinite.
  const Eigen::VectorXd inverse_sqrt_mass = sqrt_mass.cwiseInverse();
  const SparseMatrixD a =
      -(inverse_sqrt_mass.asDiagonal() * laplace.matrix * inverse_sqrt_mass.asDiagonal());
  // Shift just below zero so A − σI is positive definite and the smallest eigenvalues are the
  // largest of the inverted operator.
  const double mean_diagonal = a.diagonal().cwiseAbs().mean();
  const double sigma = -1e-6 * (mean_diagonal > 0.0 ? mean_diagonal : 1.0);
  Spectra::SparseSymShiftSolve<double> op(a);
  const int ncv = std::min(v_count, std::max(2 * k + 1, k + 20));
  Spectra::SymEigsShiftSolver<Spectra::SparseSymShiftSolve<double>> eigen(op, k, ncv, sigma);
  eigen.init();
  eigen.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10, Spectra::SortRule::SmallestAlge);
  if (eigen.info() != Spectra::CompInfo::Successful) {
    return NumericalFailureError(
        fmt::format("spectral-filter: the eigensolver did not converge for k = {} on operator {}",
                    k, laplace.name));
  }
  return std::unique_ptr<PreparedMethod>(new PreparedSpectralFilter(
      eigen.eigenvectors(), std::move(sqrt_mass), eigen.eigenvalues(), filter == "enhance", gain));
}

constexpr ParameterSpec kParameters[] = {
    {"k", ParameterType::kInteger, "50", "number of eigenvectors (lowest frequencies) used"},
    {"filter", ParameterType::kText, "lowpass",
     "lowpass (reconstruct from k harmonics) or enhance (f + (gain-1)(f - lowpass f))"},
    {"gain", ParameterType::kNumber, "2", "enhance: amplification of the detail above k"},
};

}  // namespace

MethodInfo SpectralFilterMethod() {
  return {.name = "spectral-filter",
          .description =
              "manifold-harmonics low-pass / enhancement with the first k "
              "eigenvectors of a symmetric operator (Spectra)",
          .parameters = kParameters,
          .precompute = Precompute};
}

}  // namespace dmc

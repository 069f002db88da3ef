// Smallest generalized eigenpairs K η = λ M η with Spectra's shift-invert Lanczos.
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <exception>
#include <numeric>
#include <string>
#include <vector>

#include "dmc/bspline.h"

namespace dmc {
namespace {

// (K − σM)⁻¹ through one sparse LDLᵀ, refactored whenever Spectra sets the shift.
class ShiftInvertOperator {
 public:
  using Scalar = double;
  ShiftInvertOperator(const SparseMatrixD& stiffness, const SparseMatrixD& mass)
      : stiffness_(stiffness), mass_(mass) {}
  Eigen::Index rows() const { return stiffness_.rows(); }
  Eigen::Index cols() const { return stiffness_.cols(); }
  void set_shift(const Scalar& sigma) {
    factor_.compute(stiffness_ - sigma * mass_);
    ok_ = factor_.info() == Eigen::Success;
  }
  void perform_op(const Scalar* x_in, Scalar* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    y = factor_.solve(x);
  }
  bool ok() const { return ok_; }

 private:
  const SparseMatrixD& stiffness_;
  const SparseMatrixD& mass_;
  Eigen::SimplicialLDLT<SparseMatrixD> factor_;
  bool ok_ = false;
};

SparseMatrixD Regularised(const SparseMatrixD& matrix, double relative) {
  SparseMatrixD identity(matrix.rows(), matrix.cols());
  identity.setIdentity();
  return matrix + relative * matrix.diagonal().cwiseAbs().mean() * identity;
}

}  // namespace

StatusOr<GeneralizedSpectrum> ComputeGeneralizedSpectrum(const SparseMatrixD& stiffness,
                                                         const SparseMatrixD& mass, int count) {
  const Eigen::Index n = stiffness.rows();
  if (stiffness.cols() != n || mass.rows() != n || mass.cols() != n) {
    return MismatchError(
        "generalized eigenproblem: stiffness and mass must be square and of one "
        "size");
  }
  if (count < 1 || count >= n) {
    return InvalidArgumentError("eigenpair count must be in [1, " + std::to_string(n - 1) +
                                "], got " + std::to_string(count));
  }
  const SparseMatrixD k = Regularised(stiffness, 1e-10);
  const SparseMatrixD m = Regularised(mass, 1e-10);
  // A negative shift keeps K − σM positive definite; its size follows the problem's own scale
  // (mean diagonal ratio ≈ the highest frequencies) so the smallest eigenvalues are well
  // separated from it after the inversion.
  const double scale = k.diagonal().mean() / m.diagonal().mean();
  const double sigma = -1e-3 * scale;
  ShiftInvertOperator op(k, m);
  Spectra::SparseSymMatProd<double> mass_op(m);
  // Lanczos can miss members of a multiple eigenvalue (the sphere's 2l+1 harmonics) when it
  // stops at exactly `count`: ask for a margin of extra pairs and keep the smallest `count`.
  const int wanted =
      static_cast<int>(std::min<Eigen::Index>(n - 1, count + std::max(8, count / 2)));
  const int ncv =
      static_cast<int>(std::min<Eigen::Index>(n, std::max(2 * wanted + 1, wanted + 20)));
  try {
    Spectra::SymGEigsShiftSolver<ShiftInvertOperator, Spectra::SparseSymMatProd<double>,
                                 Spectra::GEigsMode::ShiftInvert>
        solver(op, mass_op, wanted, ncv, sigma);
    if (!op.ok()) {
      return NumericalFailureError("generalized eigenproblem: K - sigma M cannot be factored");
    }
    solver.init();
    solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10);
    if (solver.info() != Spectra::CompInfo::Successful) {
      return NumericalFailureError("generalized eigenproblem: Lanczos did not converge for " +
                                   std::to_string(count) + " eigenpairs");
    }
    const Eigen::VectorXd values = solver.eigenvalues();
    const Eigen::MatrixXd vectors = solver.eigenvectors();
    std::vector<int> order(values.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return values[a] < values[b]; });
    GeneralizedSpectrum spectrum;
    spectrum.eigenvalues.resize(count);
    spectrum.eigenvectors.resize(n, count);
    for (int i = 0; i < count; ++i) {
      spectrum.eigenvalues[i] = values[order[i]];
      spectrum.eigenvectors.col(i) = vectors.col(order[i]);
    }
    return spectrum;
  } catch (const std::exception& error) {
    return NumericalFailureError(std::string("generalized eigenproblem: ") + error.what());
  }
}

StatusOr<GeneralizedSpectrum> ComputeBsplineSpectrum(const BsplineOperator& op, int count) {
  const BsplineLevel& level = op.finest();
  return ComputeGeneralizedSpectrum(-level.laplacian, level.mass, count);
}

StatusOr<GeneralizedSpectrum> LaplacianSpectrum(const LaplaceOperator& op, int count) {
  if (!op.symmetric) {
    return UnsupportedError("the spectrum needs a symmetric operator; " + op.name + " is not");
  }
  const Eigen::Index n = op.matrix.rows();
  if (op.mass_matrix.rows() == n && op.mass_matrix.cols() == n) {
    return ComputeGeneralizedSpectrum(-op.matrix, op.mass_matrix, count);
  }
  SparseMatrixD mass(n, n);
  if (op.mass.size() == n) {
    std::vector<Eigen::Triplet<double>> diagonal;
    for (Eigen::Index v = 0; v < n; ++v) diagonal.emplace_back(v, v, op.mass[v]);
    mass.setFromTriplets(diagonal.begin(), diagonal.end());
  } else {
    mass.setIdentity();
  }
  return ComputeGeneralizedSpectrum(-op.matrix, mass, count);
}

}  // namespace dmc

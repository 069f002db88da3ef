// Block LDLᵀ of a block-tridiagonal SPD matrix with diagonal coupling blocks (spacetime.h).
#include <Eigen/Cholesky>
#include <cmath>
#include <string>
#include <vector>

#include "dmc/spacetime.h"

namespace dmc {

struct BlockTridiagonalSolver::Impl {
  int block_size = 0;
  std::vector<Eigen::LLT<Eigen::MatrixXd>> schur;  // Λ(k) = L_k L_kᵀ
  std::vector<Eigen::VectorXd> coupling;           // D(k): diagonal of block (k, k+1)
};

BlockTridiagonalSolver::BlockTridiagonalSolver(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}
BlockTridiagonalSolver::BlockTridiagonalSolver(BlockTridiagonalSolver&&) noexcept = default;
BlockTridiagonalSolver& BlockTridiagonalSolver::operator=(BlockTridiagonalSolver&&) noexcept =
    default;
BlockTridiagonalSolver::~BlockTridiagonalSolver() = default;

int BlockTridiagonalSolver::block_size() const { return impl_->block_size; }
int BlockTridiagonalSolver::block_count() const { return static_cast<int>(impl_->schur.size()); }

StatusOr<BlockTridiagonalSolver> BlockTridiagonalSolver::Factor(const SparseMatrixD& matrix,
                                                                int block_size) {
  if (block_size < 1 || matrix.rows() != matrix.cols() || matrix.rows() == 0 ||
      matrix.rows() % block_size != 0) {
    return InvalidArgumentError(
        "block-tridiagonal solver: the matrix is " + std::to_string(matrix.rows()) + "×" +
        std::to_string(matrix.cols()) + ", not a square multiple of " + std::to_string(block_size));
  }
  const int blocks = static_cast<int>(matrix.rows() / block_size);
  std::vector<Eigen::MatrixXd> diagonal(blocks, Eigen::MatrixXd::Zero(block_size, block_size));
  auto impl = std::make_unique<Impl>();
  impl->block_size = block_size;
  impl->coupling.assign(std::max(blocks - 1, 0), Eigen::VectorXd::Zero(block_size));
  // Split the entries: diagonal blocks dense, coupling blocks (k, k+1) into D(k); the lower
  // coupling blocks must mirror them (symmetry), anything else is outside the pattern.
  for (int c = 0; c < matrix.outerSize(); ++c) {
    const int column_block = c / block_size, column_local = c % block_size;
    for (SparseMatrixD::InnerIterator it(matrix, c); it; ++it) {
      const double value = it.value();
      if (!std::isfinite(value)) {
        return InvalidArgumentError("block-tridiagonal solver: non-finite entry");
      }
      const int row = static_cast<int>(it.row());
      const int row_block = row / block_size, row_local = row % block_size;
      if (row_block == column_block) {
        diagonal[row_block](row_local, column_local) = value;
      } else if (std::abs(row_block - column_block) == 1 && row_local == column_local) {
        if (row_block < column_block) impl->coupling[row_block][row_local] = value;
      } else if (value != 0.0) {
        return InvalidArgumentError(
            "block-tridiagonal solver: entry (" + std::to_string(row) + ", " + std::to_string(c) +
            ") lies outside the pattern (coupling blocks must be diagonal, between neighbours)");
      }
    }
  }
  impl->schur.reserve(blocks);
  for (int k = 0; k < blocks; ++k) {
    Eigen::MatrixXd lambda = std::move(diagonal[k]);
    if (k > 0) {
      // Λ(k) = A(k,k) − D(k−1)·Λ(k−1)⁻¹·D(k−1).
      const Eigen::VectorXd& d = impl->coupling[k - 1];
      Eigen::MatrixXd solved = impl->schur[k - 1].solve(Eigen::MatrixXd(d.asDiagonal()));
      lambda.noalias() -= d.asDiagonal() * solved;
      lambda = 0.5 * (lambda + lambda.transpose()).eval();  // keep it exactly symmetric
    }
    Eigen::LLT<Eigen::MatrixXd> llt(lambda);
    if (llt.info() != Eigen::Success) {
      return NumericalFailureError("block-tridiagonal solver: Schur complement " +
                                   std::to_string(k) + " is not positive definite");
    }
    impl->schur.push_back(std::move(llt));
  }
  return BlockTridiagonalSolver(std::move(impl));
}

StatusOr<Eigen::MatrixXd> BlockTridiagonalSolver::Solve(const Eigen::MatrixXd& rhs) const {
  const int n = impl_->block_size;
  const int blocks = block_count();
  if (rhs.rows() != static_cast<Eigen::Index>(n) * blocks) {
    return MismatchError("block-tridiagonal solver: right-hand side has " +
                         std::to_string(rhs.rows()) + " rows, the matrix " +
                         std::to_string(static_cast<int64_t>(n) * blocks));
  }
  // A = (Λ + Lo)·Λ⁻¹·(Λ + Loᵀ): forward (Λ + Lo)·u = b, then backward (Λ + Loᵀ)·x = Λ·u.
  Eigen::MatrixXd u(rhs.rows(), rhs.cols());
  for (int k = 0; k < blocks; ++k) {
    Eigen::MatrixXd b = rhs.middleRows(static_cast<Eigen::Index>(k) * n, n);
    if (k > 0) {
      b -= impl_->coupling[k - 1].asDiagonal() *
           u.middleRows(static_cast<Eigen::Index>(k - 1) * n, n);
    }
    u.middleRows(static_cast<Eigen::Index>(k) * n, n) = impl_->schur[k].solve(b);
  }
  Eigen::MatrixXd x = u;
  for (int k = blocks - 2; k >= 0; --k) {
    const Eigen::MatrixXd next =
        impl_->coupling[k].asDiagonal() * x.middleRows(static_cast<Eigen::Index>(k + 1) * n, n);
    x.middleRows(static_cast<Eigen::Index>(k) * n, n) -= impl_->schur[k].solve(next);
  }
  if (!x.allFinite()) {
    return NumericalFailureError("block-tridiagonal solver: non-finite solution");
  }
  return x;
}

}  // namespace dmc

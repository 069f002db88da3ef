// Geometric multigrid over the octree levels: Gauss–Seidel relaxation, restriction Pᵀ,
// prolongation P, and a direct (LDLᵀ) solve at the coarsest level.
#include <Eigen/SparseCholesky>
#include <cmath>
#include <string>

#include "dmc/bspline.h"

namespace dmc {

struct BsplineMultigrid::Impl {
  std::vector<SparseMatrixD> systems;        // A per level, coarsest first
  std::vector<Eigen::VectorXd> diagonals;    // diag(A) per level
  std::vector<SparseMatrixD> prolongations;  // level l → l+1
  Eigen::SimplicialLDLT<SparseMatrixD> coarse;

  // Forward (or backward) Gauss–Seidel sweep; A is symmetric, so column i is row i.
  void Relax(int level, const Eigen::VectorXd& rhs, Eigen::VectorXd& x, bool forward) const {
    const SparseMatrixD& a = systems[level];
    const Eigen::VectorXd& diagonal = diagonals[level];
    const Eigen::Index n = a.cols();
    for (Eigen::Index step = 0; step < n; ++step) {
      const Eigen::Index i = forward ? step : n - 1 - step;
      if (!(diagonal[i] > 0.0)) continue;  // no coupling: nothing to relax
      double row_dot = 0.0;
      for (SparseMatrixD::InnerIterator it(a, i); it; ++it) row_dot += it.value() * x[it.row()];
      x[i] += (rhs[i] - row_dot) / diagonal[i];
    }
  }

  void Cycle(int level, const Eigen::VectorXd& rhs, Eigen::VectorXd& x,
             const MultigridOptions& options) const {
    if (level == 0) {
      x = coarse.solve(rhs);
      return;
    }
    for (int s = 0; s < options.pre_smoothing; ++s) Relax(level, rhs, x, true);
    const Eigen::VectorXd residual = rhs - systems[level] * x;
    const SparseMatrixD& p = prolongations[level - 1];
    const Eigen::VectorXd coarse_rhs = p.transpose() * residual;
    Eigen::VectorXd correction = Eigen::VectorXd::Zero(coarse_rhs.size());
    // A W-cycle visits each coarser level twice per visit of its parent (γ = 2); the coarsest
    // solve is exact, so a second visit there would change nothing.
    const int visits = options.cycle == MultigridCycle::kW && level > 1 ? 2 : 1;
    for (int v = 0; v < visits; ++v) Cycle(level - 1, coarse_rhs, correction, options);
    x += p * correction;
    for (int s = 0; s < options.post_smoothing; ++s) Relax(level, rhs, x, false);
  }
};

BsplineMultigrid::BsplineMultigrid(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BsplineMultigrid::BsplineMultigrid(BsplineMultigrid&&) noexcept = default;
BsplineMultigrid& BsplineMultigrid::operator=(BsplineMultigrid&&) noexcept = default;
BsplineMultigrid::~BsplineMultigrid() = default;

StatusOr<BsplineMultigrid> BsplineMultigrid::Create(const BsplineOperator& op,
                                                    double stiffness_weight, double mass_weight) {
  if (!(stiffness_weight >= 0.0) || !(mass_weight >= 0.0) || !std::isfinite(stiffness_weight) ||
      !std::isfinite(mass_weight) || stiffness_weight + mass_weight <= 0.0) {
    return InvalidArgumentError("multigrid weights must be finite, non-negative and not both zero");
  }
  if (op.levels.empty()) return InvalidArgumentError("the B-spline operator has no level");
  auto impl = std::make_unique<Impl>();
  for (const BsplineLevel& level : op.levels) {
    SparseMatrixD a = stiffness_weight * (-level.laplacian) + mass_weight * level.mass;
    impl->diagonals.push_back(a.diagonal());
    impl->systems.push_back(std::move(a));
    if (level.prolongation.size() > 0) impl->prolongations.push_back(level.prolongation);
  }
  // The coarse system is singular for the pure Poisson problem (constants) and may have
  // directions that vanish on the surface; a relative 1e-12 shift keeps LDLᵀ defined without
  // moving the solution measurably.
  const SparseMatrixD& coarse = impl->systems.front();
  const double mean_diagonal = impl->diagonals.front().mean();
  SparseMatrixD identity(coarse.rows(), coarse.cols());
  identity.setIdentity();
  impl->coarse.compute(coarse + 1e-12 * mean_diagonal * identity);
  if (impl->coarse.info() != Eigen::Success) {
    return NumericalFailureError("multigrid: the coarsest system (" +
                                 std::to_string(coarse.rows()) + " nodes) cannot be factored");
  }
  return BsplineMultigrid(std::move(impl));
}

void BsplineMultigrid::Cycle(const Eigen::VectorXd& rhs, Eigen::VectorXd& x,
                             const MultigridOptions& options) const {
  impl_->Cycle(level_count() - 1, rhs, x, options);
}

StatusOr<MultigridReport> BsplineMultigrid::Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x,
                                                  const MultigridOptions& options) const {
  if (rhs.size() != dimension() || x.size() != dimension()) {
    return MismatchError("multigrid: right-hand side has " + std::to_string(rhs.size()) +
                         " and the guess " + std::to_string(x.size()) + " entries, the system " +
                         std::to_string(dimension()));
  }
  const SparseMatrixD& a = impl_->systems.back();
  MultigridReport report;
  report.initial_residual = (rhs - a * x).norm();
  report.final_residual = report.initial_residual;
  const double target = options.relative_tolerance * rhs.norm();
  while (report.final_residual > target && report.cycles < options.max_cycles) {
    Cycle(rhs, x, options);
    ++report.cycles;
    report.final_residual = (rhs - a * x).norm();
    report.residual_history.push_back(report.final_residual);
    if (!std::isfinite(report.final_residual)) {
      return NumericalFailureError("multigrid: the residual became non-finite after cycle " +
                                   std::to_string(report.cycles));
    }
  }
  report.converged = report.final_residual <= target;
  return report;
}

const SparseMatrixD& BsplineMultigrid::system(int level) const { return impl_->systems[level]; }
int BsplineMultigrid::level_count() const { return static_cast<int>(impl_->systems.size()); }
int BsplineMultigrid::dimension() const { return static_cast<int>(impl_->systems.back().rows()); }

}  // namespace dmc

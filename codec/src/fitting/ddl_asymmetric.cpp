// Asymmetric data-dependent Laplacian (thesis 5.2 and 6.3.4): one weight per directed edge, each
// row unit sum. Rows do not share unknowns, so the fit splits into one small problem per vertex:
//   minimise ‖Dᵀw‖² + μ_t s ‖w − ref‖²  subject to  1ᵀw = 1,
// with D (deg×r) the ring's trajectory differences c_j − c_i. In units of s, with M = DDᵀ/s + μ_t I
// and g = μ_t ref, the KKT conditions M w = g − ν 1, 1ᵀw = 1 give
//   w = M⁻¹g − ν M⁻¹1,   ν = (1ᵀM⁻¹g − 1) / (1ᵀM⁻¹1).
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "dmc/operators.h"
#include "fitting/ddl_common.h"

namespace dmc {

StatusOr<LaplaceOperator> FitDdlAsymmetric(const MeshTopology& topology,
                                           const OperatorSource& source,
                                           const OperatorOptions& options) {
  DMC_ASSIGN_OR_RETURN(const Eigen::MatrixXd* trajectories_ptr,
                       fitting_internal::RequireTrajectories(topology, source, "ddl-asym"));
  const Eigen::MatrixXd& trajectories = *trajectories_ptr;
  if (!(options.ddl.mu >= 0.0) || !(options.ddl.min_mu >= 0.0) || !std::isfinite(options.ddl.mu) ||
      !std::isfinite(options.ddl.min_mu)) {
    return InvalidArgumentError(
        fmt::format("ddl-asym: mu ({}) and min_mu ({}) must be finite and non-negative",
                    options.ddl.mu, options.ddl.min_mu));
  }
  DMC_ASSIGN_OR_RETURN(std::vector<double> reference,
                       fitting_internal::ReferenceDirectedWeights(topology, source, options));
  const int v_count = topology.vertex_count;
  const double mu_total = options.ddl.mu + options.ddl.min_mu;
  const double scale = fitting_internal::MeanSquaredEdgeDifference(topology, trajectories);

  std::vector<double> weights(topology.ring_neighbors.size(), 0.0);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, v_count, 256), [&](const tbb::blocked_range<int>& r) {
        Eigen::MatrixXd differences, system;
        Eigen::LDLT<Eigen::MatrixXd> factor;
        for (int v = r.begin(); v < r.end(); ++v) {
          const int degree = topology.degree(v), begin = topology.ring_offsets[v];
          if (degree == 0) continue;
          if (degree == 1) {  // the constraint alone decides
            weights[begin] = 1.0;
            continue;
          }
          fitting_internal::RingDifferences(topology, trajectories, v, differences);
          system.noalias() = differences * differences.transpose() / scale;
          // The ridge also keeps M definite when the ring's differences are rank deficient
          // (degree > r + 1, planar or static data): min_mu > 0 by default.
          system.diagonal().array() += std::max(mu_total, 1e-15);
          factor.compute(system);
          const Eigen::VectorXd g =
              mu_total * Eigen::Map<const Eigen::VectorXd>(reference.data() + begin, degree);
          const Eigen::VectorXd m_inv_g = factor.solve(g);
          const Eigen::VectorXd m_inv_one = factor.solve(Eigen::VectorXd::Ones(degree));
          const double nu = (m_inv_g.sum() - 1.0) / m_inv_one.sum();
          Eigen::VectorXd w = m_inv_g - nu * m_inv_one;
          // Re-impose the unit sum exactly (spread the rounding evenly): the row must sum to 1.
          w.array() += (1.0 - w.sum()) / degree;
          Eigen::Map<Eigen::VectorXd>(weights.data() + begin, degree) = w;
        }
      });
  for (const double w : weights) {
    if (!std::isfinite(w)) {
      return NumericalFailureError("ddl-asym: a per-vertex fit produced non-finite weights");
    }
  }

  DMC_ASSIGN_OR_RETURN(
      LaplaceOperator result,
      OperatorFromWeights("ddl-asym", topology,
                          {WeightLayout::kPerDirectedEdge, std::move(weights)}, true));
  result.stats.fit_residual = fitting_internal::DeltaEnergy(result.matrix, trajectories);
  double max_error = 0.0;
  for (int v = 0; v < v_count; ++v) {
    if (topology.degree(v) > 0) {
      max_error = std::max(max_error, std::abs(1.0 + result.matrix.coeff(v, v)));
    }
  }
  result.stats.constraint_error = max_error;
  return result;
}

}  // namespace dmc

// Measures of moving cells: Gauss–Legendre rules and the appendix's two integrals.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "dmc/spacetime.h"

namespace dmc {
namespace {

// ‖a + β·b‖² = ‖b‖²·β² + 2(a·b)·β + ‖a‖²: below this ratio ‖b‖/‖a‖ the closed form's two
// antiderivative values are ~‖a‖²/‖b‖² apart in magnitude from their difference and cancel;
// 8-point Gauss–Legendre is then exact to rounding for the nearly linear integrand.
constexpr double kClosedFormMinRatio = 1e-3;

double LengthAntiderivative(double u, double c) {
  const double root = std::sqrt(u * u + c * c);
  if (c == 0.0) return 0.5 * u * std::abs(u);
  return 0.5 * (u * root + c * c * std::asinh(u / c));
}

const GaussLegendreRule& EightPointRule() {
  static const GaussLegendreRule rule = MakeGaussLegendreRule(8);
  return rule;
}

}  // namespace

GaussLegendreRule MakeGaussLegendreRule(int points) {
  points = std::max(points, 1);
  // Golub–Welsch: the nodes are the eigenvalues of the symmetric tridiagonal Jacobi matrix of
  // the Legendre recurrence, the weights 2·(first eigenvector component)².
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(points, points);
  for (int n = 1; n < points; ++n) {
    const double off = n / std::sqrt(4.0 * n * n - 1.0);
    jacobi(n, n - 1) = off;
    jacobi(n - 1, n) = off;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jacobi);
  GaussLegendreRule rule;
  rule.nodes = eigen.eigenvalues();
  rule.weights = 2.0 * eigen.eigenvectors().row(0).transpose().array().square();
  return rule;
}

double IntegrateMovingLength(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double beta0,
                             double beta1) {
  const double b_norm2 = b.squaredNorm();
  const double a_norm = a.norm();
  if (b_norm2 <= (kClosedFormMinRatio * a_norm) * (kClosedFormMinRatio * a_norm)) {
    const GaussLegendreRule& rule = EightPointRule();
    const double half = 0.5 * (beta1 - beta0), mid = 0.5 * (beta1 + beta0);
    double sum = 0.0;
    for (Eigen::Index q = 0; q < rule.nodes.size(); ++q) {
      sum += rule.weights[q] * (a + (mid + half * rule.nodes[q]) * b).norm();
    }
    return half * sum;
  }
  const double b_norm = std::sqrt(b_norm2);
  const double shift = a.dot(b) / b_norm2;
  // c from the cross product, not from ‖a‖² − (a·b)²/‖b‖², which cancels for near-parallel a, b.
  const double c = a.cross(b).norm() / b_norm2;
  return b_norm * (LengthAntiderivative(beta1 + shift, c) - LengthAntiderivative(beta0 + shift, c));
}

double IntegrateMovingTriangleArea(const Eigen::Matrix3d& start, const Eigen::Matrix3d& end,
                                   double beta0, double beta1, const GaussLegendreRule& rule) {
  const Eigen::Matrix3d motion = end - start;
  const double half = 0.5 * (beta1 - beta0), mid = 0.5 * (beta1 + beta0);
  double sum = 0.0;
  for (Eigen::Index q = 0; q < rule.nodes.size(); ++q) {
    const Eigen::Matrix3d corners = start + (mid + half * rule.nodes[q]) * motion;
    const Eigen::Vector3d e1 = (corners.row(1) - corners.row(0)).transpose();
    const Eigen::Vector3d e2 = (corners.row(2) - corners.row(0)).transpose();
    sum += rule.weights[q] * 0.5 * e1.cross(e2).norm();
  }
  return half * sum;
}

}  // namespace dmc

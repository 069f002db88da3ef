// Identity checks every Laplace operator must pass, shared by the operator and fitting tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>

#include "dmc/operators.h"

namespace dmc::testing {

// Rows sum to zero, constants are in the null space, δ is translation invariant, the pattern is
// the mesh's, the matrix is symmetric / unit-sum when the operator says so, and all is finite.
inline void ExpectOperatorIdentities(const LaplaceOperator& op, const MeshTopology& topology) {
  SCOPED_TRACE("operator " + op.name);
  const SparseMatrixD& L = op.matrix;
  const int v_count = topology.vertex_count;
  ASSERT_EQ(L.rows(), v_count);
  ASSERT_EQ(L.cols(), v_count);

  // Row sums and absolute row sums, from the stored entries.
  Eigen::VectorXd row_sum = Eigen::VectorXd::Zero(v_count);
  Eigen::VectorXd row_abs = Eigen::VectorXd::Zero(v_count);
  for (int c = 0; c < L.outerSize(); ++c) {
    for (SparseMatrixD::InnerIterator it(L, c); it; ++it) {
      ASSERT_TRUE(std::isfinite(it.value())) << "entry (" << it.row() << ", " << it.col() << ")";
      row_sum[it.row()] += it.value();
      row_abs[it.row()] += std::abs(it.value());
      if (it.row() != it.col()) {
        ASSERT_GE(RingSlot(topology, static_cast<int>(it.row()), static_cast<int>(it.col())), 0)
            << "entry off the mesh pattern at (" << it.row() << ", " << it.col() << ")";
      }
    }
  }
  for (int v = 0; v < v_count; ++v) {
    EXPECT_LE(std::abs(row_sum[v]), 1e-12 * row_abs[v] + 1e-300) << "row " << v;
  }
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(v_count);
  EXPECT_LE((L * ones).cwiseAbs().maxCoeff(), 1e-12 * std::max(1.0, row_abs.maxCoeff()));

  // Translation invariance on an arbitrary signal.
  Eigen::MatrixXd x = Eigen::MatrixXd::NullaryExpr(v_count, 3, [](Eigen::Index r, Eigen::Index c) {
    return std::sin(0.37 * static_cast<double>(r) + 1.3 * static_cast<double>(c));
  });
  Eigen::MatrixXd shifted = x;
  shifted.rowwise() += Eigen::RowVector3d(12.5, -3.0, 7.25);
  EXPECT_LE((L * shifted - L * x).cwiseAbs().maxCoeff(), 1e-10 * std::max(1.0, row_abs.maxCoeff()));

  if (op.symmetric) {
    EXPECT_EQ((SparseMatrixD(L.transpose()) - L).norm(), 0.0) << "symmetric operator";
  }
  for (int v = 0; v < v_count; ++v) {
    if (topology.degree(v) == 0) {
      EXPECT_EQ(row_abs[v], 0.0) << "isolated vertex " << v << " must have a zero row";
    } else if (op.unit_sum) {
      EXPECT_NEAR(L.coeff(v, v), -1.0, 1e-10) << "unit-sum row " << v;
    }
  }
  if (op.mass.size() > 0) {
    ASSERT_EQ(op.mass.size(), v_count);
    EXPECT_TRUE(op.mass.allFinite());
    EXPECT_GE(op.mass.minCoeff(), 0.0);
  }
}

}  // namespace dmc::testing

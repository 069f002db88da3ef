// The inner product of frame synthesis (spec §10.2): trajectories of a few vertices as Σ_k C·basis.
#pragma once

#include <cstddef>

namespace dmc {

// For each of `vertex_count` ≤ kSynthesisVertexGroup vertices i and every trajectory entry
// j < width:
//   sums[i·width + j] = Σ_{k=0}^{rank−1} coefficients[i][k] · basis[k·width + j]
// summed in binary64 in increasing k from 0.0, one multiply and one add per term (no fused
// multiply-add), so the result is bit for bit the same on every instruction set the function is
// compiled for, and the same as a sequential dot product. `coefficients[i]` points at vertex i's
// `rank` coefficients; `basis` holds the basis column by column (column k: width entries).
inline constexpr int kSynthesisVertexGroup = 4;
void SumTrajectoryProducts(const double* const* coefficients, int vertex_count, const double* basis,
                           int rank, std::ptrdiff_t width, double* sums);

}  // namespace dmc

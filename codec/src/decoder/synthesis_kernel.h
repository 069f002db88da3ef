// The inner product of frame synthesis (spec §10.2): trajectories of a few vertices as Σ_k C·basis,
// in one SIMD variant per instruction set (Google Highway), each giving the same bits.
#pragma once

#include <cstddef>

namespace dmc {

// For each of `vertex_count` ≤ kSynthesisVertexGroup vertices i and every trajectory entry
// j < stride:
//   sums[i·stride + j] = Σ_{k=0}^{rank−1} coefficients[i][k] · basis[k·stride + j]
// summed in binary64 in increasing k from 0.0, one multiply and one add per term (no fused
// multiply-add), so the result is bit for bit the same in every variant, and the same as a
// sequential dot product. `coefficients[i]` points at vertex i's `rank` coefficients; `basis`
// holds the basis column by column, each column padded to `stride` entries. stride must be a
// positive multiple of kSynthesisStrideMultiple (every variant then works in whole vectors, with
// no scalar tail); the padding entries' sums are computed like the others and mean nothing.
// vertex_count must be in [1, kSynthesisVertexGroup], rank ≥ 1. Runs the active variant
// (dmc/simd.h: the best the CPU supports unless SetSimdVariant chose another).
inline constexpr int kSynthesisVertexGroup = 4;
inline constexpr std::ptrdiff_t kSynthesisStrideMultiple = 8;  // the widest vector: 8 × binary64
void SumTrajectoryProducts(const double* const* coefficients, int vertex_count, const double* basis,
                           int rank, std::ptrdiff_t stride, double* sums);

// The same in the variant named `variant` (one of SupportedSimdVariants()), for tests and
// benchmarks; false, computing nothing, when the name is not a variant this CPU runs.
bool SumTrajectoryProductsWith(const char* variant, const double* const* coefficients,
                               int vertex_count, const double* basis, int rank,
                               std::ptrdiff_t stride, double* sums);

}  // namespace dmc

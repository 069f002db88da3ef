// The inner product of frame synthesis (spec §10.2): trajectories of a few vertices as Σ_k C·basis.
#pragma once

#include <cstddef>

namespace dmc {

// For each of `vertex_count` ≤ kSynthesisVertexGroup vertices i and every trajectory entry
// j < width:
//   sums[i·width + j] = Σ_{k=0}^{rank−1} coefficients[i][k] · basis[k·width + j]
// summed in binary64 in increasing k from 0.0, one multiply and one add per term (no fused
// multiply-add), so the result is bit for bit the same on every instruction set the function is
// built for, and the same as a sequential dot product. `coefficients[i]` points at vertex i's
// `rank` coefficients; `basis` holds the basis column by column (column k: width entries).
// vertex_count must be in [1, kSynthesisVertexGroup]. Runs the widest variant the CPU supports.
inline constexpr int kSynthesisVertexGroup = 4;
void SumTrajectoryProducts(const double* const* coefficients, int vertex_count, const double* basis,
                           int rank, std::ptrdiff_t width, double* sums);

// The instruction-set variants, for tests: each gives the same bits.
enum class SynthesisIsa { kBaseline, kAvx2, kAvx512 };
bool SynthesisIsaSupported(SynthesisIsa isa);  // built for this target and the CPU has it
void SumTrajectoryProducts(SynthesisIsa isa, const double* const* coefficients, int vertex_count,
                           const double* basis, int rank, std::ptrdiff_t width, double* sums);

}  // namespace dmc

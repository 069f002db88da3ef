#include "decoder/synthesis_kernel.h"

#include <cassert>
#include <initializer_list>

namespace dmc {
namespace {

// Eight binary64 lanes in GCC's generic vector type: one AVX-512 register, two AVX2 or four SSE2
// registers in the other variants. Every lane is one trajectory entry with its own running sum, so
// lanes never combine and the vector width cannot change a result. The layout was chosen with
// BM_StageBasisMultiply on an AVX-512 CPU (tests/bench/README.md, "Decoder design choices").
typedef double Lanes __attribute__((vector_size(64)));
constexpr int kLaneCount = 8;
constexpr int kStripVectors = 2;  // kGroup × kStripVectors sums live in registers over all k
constexpr std::ptrdiff_t kStrip = kLaneCount * kStripVectors;

// The entries are taken in strips of kStrip: a group's sums stay in registers for the whole loop
// over k, and the basis strip of each k is loaded once for the group's vertices, instead of a
// load and a store of every sum for every term.
template <int kGroup>
[[gnu::always_inline]] inline void SumGroup(const double* const* coefficients, const double* basis,
                                            int rank, std::ptrdiff_t width, double* sums) {
  std::ptrdiff_t j0 = 0;
  for (; j0 + kStrip <= width; j0 += kStrip) {
    Lanes strip[kGroup][kStripVectors] = {};
    for (int k = 0; k < rank; ++k) {
      const double* column = basis + k * width + j0;
      Lanes terms[kStripVectors];
      for (int s = 0; s < kStripVectors; ++s) {
        __builtin_memcpy(&terms[s], column + s * kLaneCount, sizeof(Lanes));  // unaligned load
      }
      for (int i = 0; i < kGroup; ++i) {
        const double c = coefficients[i][k];
        const Lanes ci = {c, c, c, c, c, c, c, c};
        for (int s = 0; s < kStripVectors; ++s) strip[i][s] += ci * terms[s];
      }
    }
    for (int i = 0; i < kGroup; ++i) {
      for (int s = 0; s < kStripVectors; ++s) {
        __builtin_memcpy(sums + i * width + j0 + s * kLaneCount, &strip[i][s], sizeof(Lanes));
      }
    }
  }
  for (int i = 0; i < kGroup; ++i) {
    for (std::ptrdiff_t j = j0; j < width; ++j) {
      double sum = 0.0;
      for (int k = 0; k < rank; ++k) sum += coefficients[i][k] * basis[k * width + j];
      sums[i * width + j] = sum;
    }
  }
}

// Every group size, inlined into each instruction-set variant below.
[[gnu::always_inline]] inline void SumAnyGroup(const double* const* coefficients, int vertex_count,
                                               const double* basis, int rank, std::ptrdiff_t width,
                                               double* sums) {
  switch (vertex_count) {
    case 4:
      return SumGroup<4>(coefficients, basis, rank, width, sums);
    case 3:
      return SumGroup<3>(coefficients, basis, rank, width, sums);
    case 2:
      return SumGroup<2>(coefficients, basis, rank, width, sums);
    default:
      assert(vertex_count == 1);
      return SumGroup<1>(coefficients, basis, rank, width, sums);
  }
}

using SumFunction = void (*)(const double* const*, int, const double*, int, std::ptrdiff_t,
                             double*);

// The variants, dispatched by hand rather than with target_clones, whose dispatcher clang before
// 18 cannot call from another translation unit (llvm-project issue 61219). The file is compiled
// with -ffp-contract=off (codec/CMakeLists.txt), so no variant fuses the multiply and the add.
void SumBaseline(const double* const* coefficients, int vertex_count, const double* basis, int rank,
                 std::ptrdiff_t width, double* sums) {
  SumAnyGroup(coefficients, vertex_count, basis, rank, width, sums);
}
#if defined(__x86_64__)
__attribute__((target("avx2"))) void SumAvx2(const double* const* coefficients, int vertex_count,
                                             const double* basis, int rank, std::ptrdiff_t width,
                                             double* sums) {
  SumAnyGroup(coefficients, vertex_count, basis, rank, width, sums);
}
__attribute__((target("avx512f"))) void SumAvx512(const double* const* coefficients,
                                                  int vertex_count, const double* basis, int rank,
                                                  std::ptrdiff_t width, double* sums) {
  SumAnyGroup(coefficients, vertex_count, basis, rank, width, sums);
}
#endif

SumFunction Variant(SynthesisIsa isa) {
  switch (isa) {
#if defined(__x86_64__)
    case SynthesisIsa::kAvx512:
      return SumAvx512;
    case SynthesisIsa::kAvx2:
      return SumAvx2;
#endif
    default:
      return SumBaseline;
  }
}

}  // namespace

bool SynthesisIsaSupported(SynthesisIsa isa) {
  switch (isa) {
    case SynthesisIsa::kBaseline:
      return true;
#if defined(__x86_64__)
    case SynthesisIsa::kAvx2:
      __builtin_cpu_init();
      return __builtin_cpu_supports("avx2");
    case SynthesisIsa::kAvx512:
      __builtin_cpu_init();
      return __builtin_cpu_supports("avx512f");
#endif
    default:
      return false;
  }
}

void SumTrajectoryProducts(SynthesisIsa isa, const double* const* coefficients, int vertex_count,
                           const double* basis, int rank, std::ptrdiff_t width, double* sums) {
  Variant(isa)(coefficients, vertex_count, basis, rank, width, sums);
}

void SumTrajectoryProducts(const double* const* coefficients, int vertex_count, const double* basis,
                           int rank, std::ptrdiff_t width, double* sums) {
  static const SumFunction best = [] {
    for (const SynthesisIsa isa : {SynthesisIsa::kAvx512, SynthesisIsa::kAvx2}) {
      if (SynthesisIsaSupported(isa)) return Variant(isa);
    }
    return Variant(SynthesisIsa::kBaseline);
  }();
  best(coefficients, vertex_count, basis, rank, width, sums);
}

}  // namespace dmc

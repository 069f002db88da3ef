// Highway compiles this file once per SIMD target (foreach_target.h re-includes it with
// HWY_TARGET set to each): the kernel below is written once, for vectors of whatever width the
// target's registers hold, and the dispatch table at the end picks among the compiled targets.
// The file is compiled with -ffp-contract=off (codec/CMakeLists.txt), so no variant fuses the
// multiply and the add.

// Every attainable target, the portable baseline included, so each can be forced and tested on
// one machine. Not: SVE and RVV, whose vectors are sizeless and cannot be held in the arrays
// below; WebAssembly SIMD and 32-bit NEON, which have no binary64 vectors in this Highway (a
// WebAssembly or ARMv7 build runs the baseline).
#include <hwy/detect_compiler_arch.h>
#ifndef HWY_COMPILE_ALL_ATTAINABLE
#define HWY_COMPILE_ALL_ATTAINABLE
#endif
#if HWY_ARCH_ARM_V7
#define DMC_NO_FLOAT64_NEON HWY_NEON
#else
#define DMC_NO_FLOAT64_NEON 0
#endif
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS                                                                \
  (HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV | HWY_WASM | HWY_WASM_EMU256 | \
   DMC_NO_FLOAT64_NEON)
#endif

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "decoder/synthesis_kernel.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "decoder/synthesis_kernel.h"

HWY_BEFORE_NAMESPACE();
namespace dmc {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A build that sets HWY_DISABLED_TARGETS itself must still leave out the targets above.
#if !HWY_HAVE_FLOAT64 || HWY_HAVE_SCALABLE
#error "synthesis_kernel.cpp: this Highway target lacks binary64 or fixed-size vectors"
#endif
static_assert(kSynthesisStrideMultiple * sizeof(double) % HWY_MAX_BYTES == 0,
              "a padded stride must be a whole number of this target's vectors");

// Vectors of accumulators per vertex in one strip: kGroup × kStripVectors sums stay in registers
// for the whole loop over k, and each basis vector of the strip is loaded once per k for all the
// group's vertices. Sixteen vector registers (SSE, AVX2) hold 4 × 3 sums, three loaded basis
// vectors and a broadcast; AVX-512's thirty-two hold 4 × 4 and more. The widths were chosen with
// BM_StageBasisMultiply (tests/bench/README.md, "SIMD variants").
#if HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL
constexpr int kStripVectors = 4;
#else
constexpr int kStripVectors = 3;
#endif

template <int kGroup, int kVectors>
HWY_INLINE void SumStrip(const double* const* HWY_RESTRICT coefficients,
                         const double* HWY_RESTRICT basis, int rank, std::ptrdiff_t stride,
                         std::ptrdiff_t j0, double* HWY_RESTRICT sums) {
  const hn::ScalableTag<double> d;
  const std::ptrdiff_t lanes = static_cast<std::ptrdiff_t>(hn::Lanes(d));
  using V = hn::Vec<decltype(d)>;
  V strip[kGroup][kVectors];
  for (int i = 0; i < kGroup; ++i) {
    for (int s = 0; s < kVectors; ++s) strip[i][s] = hn::Zero(d);
  }
  for (int k = 0; k < rank; ++k) {
    const double* column = basis + k * stride + j0;
    V terms[kVectors];
    for (int s = 0; s < kVectors; ++s) terms[s] = hn::LoadU(d, column + s * lanes);
    for (int i = 0; i < kGroup; ++i) {
      const V c = hn::Set(d, coefficients[i][k]);
      for (int s = 0; s < kVectors; ++s) strip[i][s] = hn::Add(strip[i][s], hn::Mul(c, terms[s]));
    }
  }
  for (int i = 0; i < kGroup; ++i) {
    for (int s = 0; s < kVectors; ++s) {
      hn::StoreU(strip[i][s], d, sums + i * stride + j0 + s * lanes);
    }
  }
}

// Whole strips, then single vectors: stride is a multiple of every target's lane count.
template <int kGroup>
HWY_INLINE void SumGroup(const double* const* coefficients, const double* basis, int rank,
                         std::ptrdiff_t stride, double* sums) {
  const hn::ScalableTag<double> d;
  const std::ptrdiff_t lanes = static_cast<std::ptrdiff_t>(hn::Lanes(d));
  std::ptrdiff_t j0 = 0;
  for (; j0 + kStripVectors * lanes <= stride; j0 += kStripVectors * lanes) {
    SumStrip<kGroup, kStripVectors>(coefficients, basis, rank, stride, j0, sums);
  }
  for (; j0 < stride; j0 += lanes) SumStrip<kGroup, 1>(coefficients, basis, rank, stride, j0, sums);
}

void SumTrajectoryProducts(const double* const* coefficients, int vertex_count, const double* basis,
                           int rank, std::ptrdiff_t stride, double* sums) {
  switch (vertex_count) {
    case 4:
      return SumGroup<4>(coefficients, basis, rank, stride, sums);
    case 3:
      return SumGroup<3>(coefficients, basis, rank, stride, sums);
    case 2:
      return SumGroup<2>(coefficients, basis, rank, stride, sums);
    default:
      return SumGroup<1>(coefficients, basis, rank, stride, sums);
  }
}
static_assert(kSynthesisVertexGroup == 4, "SumTrajectoryProducts has a case per group size");

}  // namespace HWY_NAMESPACE
}  // namespace dmc
HWY_AFTER_NAMESPACE();

// ---- once, after every target: the variant table and its selection --------------------------
#if HWY_ONCE

#include <atomic>
#include <cstdlib>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "dmc/simd.h"

namespace dmc {
namespace {

using SumFunction = void (*)(const double* const*, int, const double*, int, std::ptrdiff_t,
                             double*);

struct SimdVariant {
  const char* name;
  int64_t target;  // Highway's target bit
  SumFunction sum;
};

// Fastest first. A target Highway did not compile for this architecture has no row.
constexpr SimdVariant kVariants[] = {
#if HWY_TARGETS & HWY_AVX3
    {"avx512", HWY_AVX3, &N_AVX3::SumTrajectoryProducts},
#endif
#if HWY_TARGETS & HWY_AVX2
    {"avx2", HWY_AVX2, &N_AVX2::SumTrajectoryProducts},
#endif
#if HWY_TARGETS & HWY_SSE4
    {"sse4", HWY_SSE4, &N_SSE4::SumTrajectoryProducts},
#endif
#if HWY_TARGETS & HWY_SSSE3
    {"ssse3", HWY_SSSE3, &N_SSSE3::SumTrajectoryProducts},
#endif
#if HWY_TARGETS & HWY_NEON
    {"neon", HWY_NEON, &N_NEON::SumTrajectoryProducts},
#endif
#if HWY_TARGETS & HWY_EMU128
    {"baseline", HWY_EMU128, &N_EMU128::SumTrajectoryProducts},
#elif HWY_TARGETS & HWY_SCALAR
    {"baseline", HWY_SCALAR, &N_SCALAR::SumTrajectoryProducts},
#endif
};
constexpr int kVariantCount = static_cast<int>(sizeof(kVariants) / sizeof(kVariants[0]));

bool Supported(const SimdVariant& variant) {
  if (variant.target == HWY_EMU128 || variant.target == HWY_SCALAR) return true;
  // Every 64-bit Arm CPU has NEON; this Highway reports it only with the AES extension, which
  // the kernel does not use.
  if (HWY_ARCH_ARM_A64 && variant.target == HWY_NEON) return true;
  return (hwy::SupportedTargets() & variant.target) != 0;
}

int FastestSupported() {
  for (int v = 0; v < kVariantCount; ++v) {
    if (Supported(kVariants[v])) return v;
  }
  return kVariantCount - 1;
}

int FindSupported(const char* name) {
  for (int v = 0; v < kVariantCount; ++v) {
    if (std::string_view(kVariants[v].name) == name && Supported(kVariants[v])) return v;
  }
  return -1;
}

// The row synthesis runs; −1 until the first use or SetSimdVariant("auto").
std::atomic<int> active_variant{-1};

const SimdVariant& Active() {
  int v = active_variant.load(std::memory_order_relaxed);
  if (v < 0) {
    // A SetSimdVariant racing with the first use wins.
    const int fastest = FastestSupported();
    v = active_variant.compare_exchange_strong(v, fastest, std::memory_order_relaxed) ? fastest : v;
  }
  return kVariants[v];
}

// Every name a build may have, so a misspelt name and a missing instruction set get different
// errors.
constexpr std::string_view kKnownNames[] = {"avx512", "avx2", "sse4", "ssse3", "neon", "baseline"};

std::string JoinedNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

}  // namespace

void SumTrajectoryProducts(const double* const* coefficients, int vertex_count, const double* basis,
                           int rank, std::ptrdiff_t stride, double* sums) {
  Active().sum(coefficients, vertex_count, basis, rank, stride, sums);
}

bool SumTrajectoryProductsWith(const char* variant, const double* const* coefficients,
                               int vertex_count, const double* basis, int rank,
                               std::ptrdiff_t stride, double* sums) {
  const int v = FindSupported(variant);
  if (v < 0) return false;
  kVariants[v].sum(coefficients, vertex_count, basis, rank, stride, sums);
  return true;
}

std::vector<std::string> SupportedSimdVariants() {
  std::vector<std::string> names;
  for (const SimdVariant& variant : kVariants) {
    if (Supported(variant)) names.emplace_back(variant.name);
  }
  return names;
}

std::string ActiveSimdVariant() { return Active().name; }

Status SetSimdVariant(std::string_view name) {
  if (name == "auto") {
    active_variant.store(FastestSupported(), std::memory_order_relaxed);
    return Status::Ok();
  }
  bool known = false;
  for (const std::string_view candidate : kKnownNames) known = known || candidate == name;
  if (!known) {
    return InvalidArgumentError("SIMD variant '" + std::string(name) + "' is not one of " +
                                JoinedNames({std::begin(kKnownNames), std::end(kKnownNames)}) +
                                " or auto");
  }
  const int v = FindSupported(std::string(name).c_str());
  if (v < 0) {
    return UnsupportedError("SIMD variant '" + std::string(name) +
                            "' is not available on this CPU or build (available: " +
                            JoinedNames(SupportedSimdVariants()) + ")");
  }
  active_variant.store(v, std::memory_order_relaxed);
  return Status::Ok();
}

Status SetSimdVariantFromEnvironment() {
  const char* value = std::getenv("DMC_SIMD");
  if (value == nullptr || *value == '\0') return Status::Ok();
  return SetSimdVariant(value).WithContext("DMC_SIMD");
}

}  // namespace dmc

#endif  // HWY_ONCE

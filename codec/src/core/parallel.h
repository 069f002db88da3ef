// Internal: the parallel loops of the decoder and its solvers, on oneTBB (DMC_WITH_TBB, the native
// build) or in order on the calling thread (the WebAssembly decoder, which has no threads). Bodies
// must give the same result in any order, as TBB's already must.
#pragma once

#ifndef DMC_WITH_TBB
#define DMC_WITH_TBB 1
#endif

#if DMC_WITH_TBB
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#endif

#include <utility>

namespace dmc::core_internal {

// body(i) for every i in [begin, end).
template <typename Index, typename Body>
void ParallelFor(Index begin, Index end, const Body& body) {
#if DMC_WITH_TBB
  tbb::parallel_for(begin, end, body);
#else
  for (Index i = begin; i < end; ++i) body(i);
#endif
}

// Runs both functions, possibly at once.
template <typename First, typename Second>
void ParallelInvoke(const First& first, const Second& second) {
#if DMC_WITH_TBB
  tbb::parallel_invoke(first, second);
#else
  first();
  second();
#endif
}

// One T per thread, each a copy of the prototype on first use.
template <typename T>
class PerThread {
 public:
  PerThread() = default;
  explicit PerThread(const T& prototype) : values_(prototype) {}
  T& local() {
#if DMC_WITH_TBB
    return values_.local();
#else
    return values_;
#endif
  }

 private:
#if DMC_WITH_TBB
  tbb::enumerable_thread_specific<T> values_;
#else
  T values_;
#endif
};

}  // namespace dmc::core_internal

// Keeps the BLAS behind CHOLMOD single-threaded while the codec factors and solves.
//
// Why: the supernodes of mesh normal matrices are small dense blocks, where OpenBLAS's thread
// start-up costs more than it saves (dmc_bench, 10k vertices, 2 cores: factorisation 47 ms with
// one BLAS thread against 105 ms with two, solve 7 ms against 25 ms), and the codec already runs
// independent segments in parallel with TBB, which a threaded BLAS would oversubscribe.
//
// Contract: while at least one guard lives, OpenBLAS (when it is the BLAS in the process; looked
// up at run time, so any other BLAS is left alone) runs on one thread; when the last guard dies
// the caller's thread count is restored. Guards may be created concurrently from any thread.
#pragma once

namespace dmc {

class ScopedSingleThreadedBlas {
 public:
  ScopedSingleThreadedBlas();
  ~ScopedSingleThreadedBlas();
  ScopedSingleThreadedBlas(const ScopedSingleThreadedBlas&) = delete;
  ScopedSingleThreadedBlas& operator=(const ScopedSingleThreadedBlas&) = delete;
};

}  // namespace dmc

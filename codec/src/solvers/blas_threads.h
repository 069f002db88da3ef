// Threading of the libraries behind the codec's sparse factorisations: the BLAS under CHOLMOD
// single-threaded (ScopedSingleThreadedBlas) and CHOLMOD's own OpenMP regions serial
// (ScopedSerialOpenMp), while the codec factors and solves; its parallelism is TBB's.
#pragma once

namespace dmc {

// Why one BLAS thread: the supernodes of mesh normal matrices are small dense blocks, where
// OpenBLAS's thread start-up costs more than it saves (dmc_bench, 10k vertices, 2 cores:
// factorisation 47 ms with one BLAS thread against 105 ms with two, solve 7 ms against 25 ms), and
// the codec already runs independent segments in parallel with TBB, which a threaded BLAS would
// oversubscribe.
//
// Contract: while at least one guard lives, OpenBLAS (when it is the BLAS in the process; looked
// up at run time, so any other BLAS is left alone) runs on one thread; when the last guard dies
// the caller's thread count is restored. Guards may be created concurrently from any thread.
class ScopedSingleThreadedBlas {
 public:
  ScopedSingleThreadedBlas();
  ~ScopedSingleThreadedBlas();
  ScopedSingleThreadedBlas(const ScopedSingleThreadedBlas&) = delete;
  ScopedSingleThreadedBlas& operator=(const ScopedSingleThreadedBlas&) = delete;
};

// Keeps the OpenMP parallel regions inside CHOLMOD serial on the calling thread.
//
// Why: CHOLMOD (SuiteSparse 5) opens an OpenMP region with a fixed 4 threads for every large
// enough supernode; on 2 cores, and inside the codec's own TBB tasks, each becomes a fork-join
// over oversubscribed threads, and futex waits took about a third of the factorisation's samples.
// Factorising the 10k-vertex, rank-60 normal matrix (dmc_bench BM_StageFactorisation) took 74–85
// ms with them and 25.6 ms without; the loops they split are independent copies, so the factor is
// bit for bit the same.
//
// Contract: while the guard lives, OpenMP's max-active-levels of the calling thread is 0 (every
// region it opens runs on that thread alone); the thread's previous value is restored when the
// guard dies. It is a per-thread setting (OpenMP 5 data-environment ICV, as libgomp implements
// it), so other threads of the process are not affected. Without an OpenMP runtime in the
// process (looked up at run time) the guard does nothing.
class ScopedSerialOpenMp {
 public:
  ScopedSerialOpenMp();
  ~ScopedSerialOpenMp();
  ScopedSerialOpenMp(const ScopedSerialOpenMp&) = delete;
  ScopedSerialOpenMp& operator=(const ScopedSerialOpenMp&) = delete;

 private:
  int saved_levels_ = -1;  // -1: nothing to restore
};

}  // namespace dmc

#include "solvers/blas_threads.h"

#include <dlfcn.h>

#include <mutex>

namespace dmc {
namespace {

// An integer setting of a runtime library in the process (OpenBLAS's thread count, OpenMP's
// max-active-levels), looked up at run time so that the codec works with any BLAS and without an
// OpenMP runtime; both functions null when either is missing.
struct IntSetting {
  void (*set)(int) = nullptr;
  int (*get)() = nullptr;
};

IntSetting LookUpSetting(const char* set_name, const char* get_name) {
  IntSetting found;
  found.set = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, set_name));
  found.get = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, get_name));
  if (found.set == nullptr || found.get == nullptr) found = IntSetting();
  return found;
}

const IntSetting& OpenBlasThreads() {
  static const IntSetting setting =
      LookUpSetting("openblas_set_num_threads", "openblas_get_num_threads");
  return setting;
}

const IntSetting& OpenMpActiveLevels() {
  static const IntSetting setting =
      LookUpSetting("omp_set_max_active_levels", "omp_get_max_active_levels");
  return setting;
}

std::mutex guard_mutex;
int live_guards = 0;
int saved_threads = 1;

}  // namespace

ScopedSingleThreadedBlas::ScopedSingleThreadedBlas() {
  const IntSetting& threads = OpenBlasThreads();
  if (threads.set == nullptr) return;
  std::lock_guard<std::mutex> lock(guard_mutex);
  if (live_guards++ == 0) {
    saved_threads = threads.get();
    if (saved_threads != 1) threads.set(1);
  }
}

ScopedSingleThreadedBlas::~ScopedSingleThreadedBlas() {
  const IntSetting& threads = OpenBlasThreads();
  if (threads.set == nullptr) return;
  std::lock_guard<std::mutex> lock(guard_mutex);
  if (--live_guards == 0 && saved_threads != 1) threads.set(saved_threads);
}

ScopedSerialOpenMp::ScopedSerialOpenMp() {
  const IntSetting& levels = OpenMpActiveLevels();
  if (levels.set == nullptr) return;
  saved_levels_ = levels.get();
  if (saved_levels_ != 0) levels.set(0);
}

ScopedSerialOpenMp::~ScopedSerialOpenMp() {
  if (saved_levels_ > 0) OpenMpActiveLevels().set(saved_levels_);
}

}  // namespace dmc

#include "solvers/blas_threads.h"

#include <dlfcn.h>

#include <mutex>

namespace dmc {
namespace {

using SetThreads = void (*)(int);
using GetThreads = int (*)();

struct OpenBlasControls {
  SetThreads set = nullptr;
  GetThreads get = nullptr;
};

const OpenBlasControls& Controls() {
  static const OpenBlasControls controls = [] {
    OpenBlasControls found;
    found.set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    found.get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
    if (found.set == nullptr || found.get == nullptr) found = OpenBlasControls();
    return found;
  }();
  return controls;
}

std::mutex guard_mutex;
int live_guards = 0;
int saved_threads = 1;

}  // namespace

ScopedSingleThreadedBlas::ScopedSingleThreadedBlas() {
  const OpenBlasControls& controls = Controls();
  if (controls.set == nullptr) return;
  std::lock_guard<std::mutex> lock(guard_mutex);
  if (live_guards++ == 0) {
    saved_threads = controls.get();
    if (saved_threads != 1) controls.set(1);
  }
}

ScopedSingleThreadedBlas::~ScopedSingleThreadedBlas() {
  const OpenBlasControls& controls = Controls();
  if (controls.set == nullptr) return;
  std::lock_guard<std::mutex> lock(guard_mutex);
  if (--live_guards == 0 && saved_threads != 1) controls.set(saved_threads);
}

namespace {

using SetLevels = void (*)(int);
using GetLevels = int (*)();

struct OpenMpControls {
  SetLevels set = nullptr;
  GetLevels get = nullptr;
};

const OpenMpControls& OpenMp() {
  static const OpenMpControls controls = [] {
    OpenMpControls found;
    found.set = reinterpret_cast<SetLevels>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
    found.get = reinterpret_cast<GetLevels>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
    if (found.set == nullptr || found.get == nullptr) found = OpenMpControls();
    return found;
  }();
  return controls;
}

}  // namespace

ScopedSerialOpenMp::ScopedSerialOpenMp() {
  const OpenMpControls& controls = OpenMp();
  if (controls.set == nullptr) return;
  saved_levels_ = controls.get();
  if (saved_levels_ != 0) controls.set(0);
}

ScopedSerialOpenMp::~ScopedSerialOpenMp() {
  if (saved_levels_ > 0) OpenMp().set(saved_levels_);
}

}  // namespace dmc

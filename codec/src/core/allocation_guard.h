// Internal: the last line of defence of the no-exception contract (dmc/status.h) at the public
// API. The library reports its own failures as Status, but the standard library, Eigen, CHOLMOD's
// C++ wrappers and TBB report exhausted memory by throwing; a public entry point whose work
// allocates runs it through GuardAllocation, so that becomes kResourceLimit naming the step.
#pragma once

#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

#include "dmc/status.h"

namespace dmc::core_internal {

// Runs `work` (returning Status or StatusOr<T>) and turns std::bad_alloc (and std::length_error,
// a container asked for more than it can address) into kResourceLimit "out of memory while
// <what>". Other exceptions are bugs and are left to propagate.
template <typename Work>
auto GuardAllocation(std::string_view what, Work&& work) -> std::invoke_result_t<Work> {
  try {
    return work();
  } catch (const std::bad_alloc&) {
    return ResourceLimitError("out of memory while " + std::string(what));
  } catch (const std::length_error&) {
    return ResourceLimitError("out of memory while " + std::string(what) +
                              " (a container exceeded its maximum size)");
  }
}

}  // namespace dmc::core_internal

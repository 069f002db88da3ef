// The 1.1 basis syntax's shared pieces (spec §8.3).
#include <algorithm>

#include "bitstream/syntax.h"

namespace dmc::format {

int BasisContextGroup(int column, int depth) {
  (void)column;
  return std::clamp(depth - kMinBasisBits, 0, kBasisColumnGroups - 1);
}

}  // namespace dmc::format

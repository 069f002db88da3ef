// Frozen numeric identifiers that appear in .dmc streams.
//
// Contract: every value in this header is part of the bitstream format. A value, once published,
// NEVER changes and is never reused for something else, even if the thing it names is retired;
// new entries are only appended with fresh values. 0 is reserved in every enum as "invalid / not
// set", so a zeroed field never decodes as a real choice.
#pragma once

#include <cstdint>

namespace dmc {

// ---------------------------------------------------------------------------------------------
// Discrete Laplace operators (see dmc/operators.h for what each computes). Owned by the operator
// module; the decoder rebuilds the operator a stream names from connectivity plus, depending on
// the operator, a decoded reference frame (geometric operators) or decoded weights (DDL).
// Values never change.
enum class OperatorId : uint8_t {
  kInvalid = 0,
  kKirchhoff = 1,  // graph Laplacian: w_ij = 1                    (connectivity only)
  kTutte = 2,      // w_ij = 1 / deg(i)                            (connectivity only)
  kCotan = 3,      // cotangent weights, each row scaled to unit sum (reference frame)
  kCotanArea = 4,  // cotangent weights / mixed Voronoi area       (reference frame)
  kCotanSym = 5,   // symmetric cotangent weights (DEC operator)   (reference frame)
  kMeanValue = 6,  // Floater's mean value weights, unit sum       (reference frame)
  kDdl = 7,        // data-dependent Laplacian, symmetric          (one weight per edge)
  kDdlAsym = 8,    // data-dependent Laplacian, asymmetric         (one weight per directed edge)
};

}  // namespace dmc

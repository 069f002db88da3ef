// Rate control: the residual step that meets EncoderOptions::target_bpfv or target_sted, found by
// bisection over whole encodes.
#pragma once

#include <functional>

#include "dmc/encoder.h"
#include "dmc/status.h"

namespace dmc {

// Whether the options ask for a rate (target_bpfv) or a distortion (target_sted).
bool HasRateTarget(const EncoderOptions& options);

// Whether an encode's report meets the options' target (bpfv from the file size, or STED as
// measured by decoding).
bool MeetsRateTarget(const EncoderOptions& options, const EncodeReport& report);

// Rate control: bisection on the residual step, 2^-1 … 2^-24 of the diagonal, in 12 halvings of
// the interval in bits (rank follows the step automatically). Rate falls and distortion rises
// monotonically with the step. `trial` encodes with the options it is given (the targets cleared,
// residual_step set) and says whether the result meets the target. The search moves toward the
// finest step that meets a rate target and the coarsest that meets a distortion target, so the
// last trial that met it is the choice: `trial` keeps it. kInvalidArgument when none met it.
Status SearchResidualStep(const EncoderOptions& options, double diagonal,
                          const std::function<StatusOr<bool>(const EncoderOptions&)>& trial);

}  // namespace dmc

// Validation of EncoderOptions: every field's range, and the combinations the encoder refuses.
#pragma once

#include "dmc/encoder.h"
#include "dmc/status.h"

namespace dmc {

// kInvalidArgument naming the field and its valid range; the operator name as CodecOperatorId
// checks it.
Status ValidateOptions(const EncoderOptions& options);

}  // namespace dmc

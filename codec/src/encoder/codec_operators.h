// The operators a .dmc stream can name (the codec rows of kOperatorTraits, dmc/operator_traits.h),
// by their registry names: what `EncoderOptions::operator_name` may be.
#pragma once

#include <string_view>

#include "dmc/status.h"
#include "dmc/wire_ids.h"

namespace dmc {

// kNotFound for a name no operator has, kUnsupported for an operator the codec cannot carry; both
// messages list the codec's operators.
StatusOr<OperatorId> CodecOperatorId(std::string_view name);

// The registry name of a codec operator ("unknown" for any other id).
std::string_view CodecOperatorName(OperatorId id);

}  // namespace dmc

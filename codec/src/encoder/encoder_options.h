// Validation of EncoderOptions (ValidateOptions) is public, with the option table, in
// dmc/encoder_options.h; the encoder's files include it through here.
#pragma once

#include "dmc/encoder_options.h"

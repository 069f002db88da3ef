// The encoder's options as one declarative table, read by everything that exposes them: `dmc
// encode`'s flags, dmc.encode()'s keywords and the conformance manifests' "encoder_options". Each
// knob has one name: the Python keyword and the manifest key are the name, the CLI flag is --name
// with '-' for '_' (every switch also as --no-name). Defaults are
// EncoderOptions's own; the table only names, types and describes its fields.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "dmc/encoder.h"
#include "dmc/status.h"

namespace dmc {

// The EncoderOptions field an option sets; its alternative is the option's type.
using EncoderOptionField = std::variant<int EncoderOptions::*, double EncoderOptions::*,
                                        bool EncoderOptions::*, std::string EncoderOptions::*>;

struct EncoderOptionSpec {
  std::string_view name;  // lower case with underscores
  EncoderOptionField field;
  std::string_view help;
  // Whether the option can change the stream's bytes; only those are recorded in manifests.
  bool shapes_stream = true;
};

// Every option, in EncoderOptions's order.
std::span<const EncoderOptionSpec> EncoderOptionTable();

// The option of that name; nullptr when there is none.
const EncoderOptionSpec* FindEncoderOption(std::string_view name);

// How an option is named where a message shows it.
enum class OptionSpelling : uint8_t {
  kName,     // "ddl_mu": the library, Python keywords, manifests
  kCliFlag,  // "--ddl-mu"
};
std::string SpellOption(std::string_view name, OptionSpelling spelling);

// kInvalidArgument naming the option at fault (spelt as `spelling`) and its valid range;
// kNotFound / kUnsupported from the operator name as the codec's operator list checks it. Encode
// and EncodeStreaming run it with OptionSpelling::kName before any pass over the frames (Encode
// validates the sequence first).
Status ValidateOptions(const EncoderOptions& options,
                       OptionSpelling spelling = OptionSpelling::kName);

// The rule between EncoderOptions::effort and the switches that restrict the search: false always
// turns a search off; true (the default) leaves it to the effort. A library caller's struct
// cannot tell a default from a choice, so the front ends pass the options their user named
// (`given`, table names) and this refuses a switch named true that asks for a search the effort
// does not do: kInvalidArgument for ddl_fallback below kFallbackEffort and rank_search below
// kRankSearchEffort (spelt as `spelling`). `dmc encode` and dmc.encode() run it after
// ValidateOptions.
Status CheckGivenSwitches(const EncoderOptions& options, std::span<const std::string> given,
                          OptionSpelling spelling = OptionSpelling::kName);

}  // namespace dmc

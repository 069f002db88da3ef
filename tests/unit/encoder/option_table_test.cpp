// The encoder option table: one distinct name per EncoderOptions field, and validation messages
// that name the option at fault in the spelling asked for.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <variant>

#include "dmc/encoder_options.h"
#include "dmc/operator_traits.h"

namespace dmc {
namespace {

using ::testing::HasSubstr;

TEST(EncoderOptionTable, NamesAreDistinctSnakeCaseAndFound) {
  std::set<std::string> names;
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    EXPECT_TRUE(names.insert(std::string(spec.name)).second) << spec.name;
    EXPECT_EQ(spec.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz_"), std::string::npos)
        << spec.name;
    EXPECT_FALSE(spec.help.empty()) << spec.name;
    EXPECT_EQ(FindEncoderOption(spec.name), &spec);
  }
  EXPECT_EQ(FindEncoderOption("ddl_regularization"), nullptr);
  EXPECT_EQ(SpellOption("ddl_mu", OptionSpelling::kName), "ddl_mu");
  EXPECT_EQ(SpellOption("ddl_mu", OptionSpelling::kCliFlag), "--ddl-mu");
}

// The operator option's help lists exactly the operators a stream can carry, in the traits
// table's order: the help is written out, so this keeps it true when the table changes.
TEST(EncoderOptionTable, OperatorHelpListsTheCodecOperators) {
  const EncoderOptionSpec* spec = FindEncoderOption("operator");
  ASSERT_NE(spec, nullptr);
  std::string names;
  for (const OperatorTraits& traits : kOperatorTraits) {
    if (traits.codec()) names += (names.empty() ? "" : ", ") + std::string(traits.name);
  }
  const std::string help(spec->help);
  ASSERT_NE(help.find(": "), std::string::npos) << help;
  EXPECT_EQ(help.substr(help.find(": ") + 2), names);
}

// Setting each option through the table writes its own field and no other: every row holds a
// distinct field of EncoderOptions.
TEST(EncoderOptionTable, EachRowSetsItsOwnField) {
  const auto changed = [](const EncoderOptionSpec& spec) {
    EncoderOptions options;
    std::visit(
        [&](auto field) {
          auto& value = options.*field;
          using T = std::remove_reference_t<decltype(value)>;
          if constexpr (std::is_same_v<T, bool>) {
            value = !value;
          } else if constexpr (std::is_same_v<T, std::string>) {
            value += "-changed";
          } else {
            value = value + 7;
          }
        },
        spec.field);
    return options;
  };
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    const EncoderOptions options = changed(spec);
    const EncoderOptions defaults;
    for (const EncoderOptionSpec& other : EncoderOptionTable()) {
      const bool equal =
          std::visit([&](auto field) { return options.*field == defaults.*field; }, other.field);
      EXPECT_EQ(equal, &other != &spec) << "setting " << spec.name << ", " << other.name;
    }
  }
}

TEST(EncoderOptionTable, OnlyMeasureLeavesTheStreamAlone) {
  for (const EncoderOptionSpec& spec : EncoderOptionTable()) {
    EXPECT_EQ(spec.shapes_stream, spec.name != "measure") << spec.name;
  }
}

struct BadValue {
  std::string option;  // the table name the message must carry
  std::function<void(EncoderOptions&)> set;
};

TEST(ValidateOptions, MessagesNameTheOptionInTheSpellingAsked) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const BadValue cases[] = {
      {"rank", [](EncoderOptions& o) { o.rank = -1; }},
      {"basis_bits", [](EncoderOptions& o) { o.basis_bits = 1; }},
      {"residual_bits", [](EncoderOptions& o) { o.residual_bits = 31; }},
      {"residual_step", [](EncoderOptions& o) { o.residual_step = -1.0; }},
      {"rank_threshold", [](EncoderOptions& o) { o.rank_threshold = 0.0; }},
      {"anchors", [](EncoderOptions& o) { o.anchors = -2; }},
      {"anchor_step_ratio", [&](EncoderOptions& o) { o.anchor_step_ratio = nan; }},
      {"residual_rdo_lambda", [](EncoderOptions& o) { o.residual_rdo_lambda = -0.1; }},
      {"segment_frames", [](EncoderOptions& o) { o.segment_frames = -1; }},
      {"reference_bits", [](EncoderOptions& o) { o.reference_bits = 3; }},
      {"weight_bits", [](EncoderOptions& o) { o.weight_bits = 21; }},
      {"ddl_dead_zone", [](EncoderOptions& o) { o.ddl_dead_zone = 0.25; }},
      {"ddl_mu", [](EncoderOptions& o) { o.ddl_mu = -0.1; }},
      {"target_bpfv", [](EncoderOptions& o) { o.target_bpfv = -1.0; }},
      {"target_sted", [](EncoderOptions& o) { o.target_sted = HUGE_VAL; }},
  };
  for (const BadValue& bad : cases) {
    ASSERT_NE(FindEncoderOption(bad.option), nullptr) << bad.option;
    EncoderOptions options;
    bad.set(options);
    const Status named = ValidateOptions(options);
    EXPECT_EQ(named.code(), ErrorCode::kInvalidArgument) << bad.option;
    EXPECT_THAT(named.message(), ::testing::StartsWith(bad.option + " ")) << bad.option;
    const Status flagged = ValidateOptions(options, OptionSpelling::kCliFlag);
    EXPECT_THAT(flagged.message(),
                ::testing::StartsWith(SpellOption(bad.option, OptionSpelling::kCliFlag) + " "));
  }
  EncoderOptions options;
  options.basis_bits = 40;
  EXPECT_EQ(ValidateOptions(options).message(), "basis_bits must be in [2, 16], got 40");
  options = {};
  options.ddl_mu = -1.0;
  EXPECT_EQ(ValidateOptions(options, OptionSpelling::kCliFlag).message(), "--ddl-mu must be >= 0");
  options = {};
  options.target_bpfv = 2.0;
  options.target_sted = 0.01;
  EXPECT_EQ(ValidateOptions(options).message(), "give target_bpfv or target_sted, not both");
  EXPECT_EQ(ValidateOptions(options, OptionSpelling::kCliFlag).message(),
            "give --target-bpfv or --target-sted, not both");
  EXPECT_TRUE(ValidateOptions(EncoderOptions{}).ok());
}

}  // namespace
}  // namespace dmc

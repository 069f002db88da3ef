// The operators the encoder accepts by name: the codec rows of kOperatorTraits, and which error a
// name that is not one of them gets.
#include "encoder/codec_operators.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "dmc/operator_traits.h"

namespace dmc {
namespace {

using ::testing::HasSubstr;

constexpr const char* kCodecList =
    "(codec operators: ddl, tutte, kirchhoff, cotan, cotan-area, cotan-sym, mean-value)";

TEST(CodecOperators, EveryCodecRowRoundTripsByName) {
  int codec_rows = 0;
  for (const OperatorTraits& traits : kOperatorTraits) {
    if (!traits.codec()) continue;
    ++codec_rows;
    const StatusOr<OperatorId> id = CodecOperatorId(traits.name);
    ASSERT_TRUE(id.ok()) << id.status().ToString();
    EXPECT_EQ(*id, traits.id);
    EXPECT_EQ(CodecOperatorName(traits.id), traits.name);
  }
  EXPECT_EQ(codec_rows, 7);
  EXPECT_EQ(CodecOperatorName(OperatorId::kDdlAsym), "unknown");
  EXPECT_EQ(CodecOperatorName(OperatorId::kInvalid), "unknown");
}

TEST(CodecOperators, OperatorsTheCodecCannotCarryAreUnsupportedOthersUnknown) {
  for (const char* name : {"ddl-asym", "spacetime", "bspline"}) {
    const Status status = CodecOperatorId(name).status();
    EXPECT_EQ(status.code(), ErrorCode::kUnsupported) << name;
    EXPECT_EQ(status.message(),
              "operator '" + std::string(name) + "' cannot be used by the codec " + kCodecList);
  }
  const Status unknown = CodecOperatorId("laplace-beltrami").status();
  EXPECT_EQ(unknown.code(), ErrorCode::kNotFound);
  EXPECT_THAT(unknown.message(), HasSubstr("unknown operator 'laplace-beltrami' "));
  EXPECT_THAT(unknown.message(), HasSubstr(kCodecList));
}

}  // namespace
}  // namespace dmc

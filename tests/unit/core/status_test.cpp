#include "dmc/status.h"

#include <gtest/gtest.h>

namespace dmc {
namespace {

StatusOr<int> ParsePositive(int x) {
  if (x <= 0) return InvalidArgumentError("x must be positive, got " + std::to_string(x));
  return x;
}

Status UsesMacros(int x, int* out) {
  DMC_ASSIGN_OR_RETURN(const int value, ParsePositive(x));
  DMC_RETURN_IF_ERROR(value > 100 ? UnsupportedError("too big") : Status::Ok());
  *out = value;
  return Status::Ok();
}

TEST(Status, OkAndErrorsCarryCodeAndMessage) {
  EXPECT_TRUE(Status::Ok().ok());
  const Status error = ParseError("bad line 3");
  EXPECT_FALSE(error.ok());
  EXPECT_EQ(error.code(), ErrorCode::kParseError);
  EXPECT_EQ(error.ToString(), "parse-error: bad line 3");
  EXPECT_EQ(error.WithContext("a.obj").message(), "a.obj: bad line 3");
  EXPECT_EQ(error.WithContext("a.obj").code(), ErrorCode::kParseError);
}

TEST(Status, ExitCodesAreDistinctPerClass) {
  EXPECT_EQ(ExitCodeFor(ErrorCode::kOk), 0);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kInvalidArgument), 11);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kCorruptStream), 17);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kInternal), 21);
  EXPECT_EQ(ExitCodeFor(ErrorCode::kResourceLimit), 22);
}

TEST(Status, CodeNamesArePinned) {
  EXPECT_EQ(ErrorCodeName(ErrorCode::kInvalidSequence), "invalid-sequence");
  EXPECT_EQ(ErrorCodeName(ErrorCode::kTruncatedStream), "truncated-stream");
  EXPECT_EQ(ErrorCodeName(ErrorCode::kNotFound), "not-found");
  EXPECT_EQ(ErrorCodeName(ErrorCode::kResourceLimit), "resource-limit");
}

TEST(StatusOr, MacrosPropagateTheCause) {
  int out = 0;
  EXPECT_TRUE(UsesMacros(5, &out).ok());
  EXPECT_EQ(out, 5);
  const Status negative = UsesMacros(-1, &out);
  EXPECT_EQ(negative.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(negative.message(), "x must be positive, got -1");
  EXPECT_EQ(UsesMacros(101, &out).code(), ErrorCode::kUnsupported);
}

TEST(StatusOr, OkStatusIsAnInternalError) {
  StatusOr<int> bad(Status::Ok());
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kInternal);
}

}  // namespace
}  // namespace dmc

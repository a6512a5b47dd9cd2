#include "pipeline/core/status.h"

#include <gtest/gtest.h>

namespace px {
namespace {

StatusOr<int> Half(int x) {
  if (x % 2 != 0) return InvalidArgumentError("x=" + std::to_string(x) + " is odd");
  return x / 2;
}

StatusOr<int> Quarter(int x) {
  PX_ASSIGN_OR_RETURN(int half, Half(x));
  PX_ASSIGN_OR_RETURN(int quarter, Half(half));
  return quarter;
}

TEST(StatusTest, OkAndErrorsCarryCodeAndMessage) {
  EXPECT_TRUE(OkStatus().ok());
  Status s = DataLossError("view 4: 100 bytes, want 200");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kDataLoss);
  EXPECT_EQ(s.ToString(), "DATA_LOSS: view 4: 100 bytes, want 200");
  EXPECT_EQ(s.WithContext("recording /tmp/r").message(), "recording /tmp/r: view 4: 100 bytes, want 200");
}

TEST(StatusTest, EveryCodeNameReadsBackAsItsCode) {
  for (StatusCode code : {StatusCode::kOk, StatusCode::kCancelled, StatusCode::kDataLoss, StatusCode::kAborted}) {
    EXPECT_EQ(StatusCodeFromName(StatusCodeName(code)), code) << StatusCodeName(code);
  }
  EXPECT_EQ(StatusCodeFromName("ABORTED"), StatusCode::kAborted);
  EXPECT_EQ(StatusCodeFromName("SEGFAULT"), std::nullopt);
}

TEST(StatusTest, AssignOrReturnPropagatesTheFirstError) {
  EXPECT_EQ(*Quarter(8), 2);
  StatusOr<int> odd = Quarter(6);
  ASSERT_FALSE(odd.ok());
  EXPECT_EQ(odd.status().message(), "x=3 is odd");
}

TEST(StatusDeathTest, ValueOfAnErrorAborts) {
  StatusOr<int> bad = Half(3);
  EXPECT_DEATH((void)bad.value(), "StatusOr::value\\(\\) on error");
}

}  // namespace
}  // namespace px

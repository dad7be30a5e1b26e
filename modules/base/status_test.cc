#include "base/status.h"

#include <gtest/gtest.h>

namespace selfcal {
namespace {

TEST(Status, DefaultIsOk) {
  Status s;
  EXPECT_TRUE(s.ok());
  EXPECT_EQ(s.ToString(), "ok");
}

TEST(Status, ErrorCarriesCodeAndMessage) {
  Status s = Status::Error(ErrorCode::kInvalidInput, "unknown key `max_velocty`");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kInvalidInput);  // the library says what went wrong; app chooses exit 2
  EXPECT_EQ(s.ToString(), "invalid_input: unknown key `max_velocty`");
}

TEST(Status, DetailTravelsWithTheErrorOnly) {
  const Status plain = Status::Error(ErrorCode::kHardware, "camera gone");
  EXPECT_STREQ(plain.detail_domain(), "");
  EXPECT_EQ(plain.detail(), 0);
  const Status detailed = plain.WithDetail("capture", 7);
  EXPECT_STREQ(detailed.detail_domain(), "capture");
  EXPECT_EQ(detailed.detail(), 7);
  EXPECT_EQ(detailed.code(), ErrorCode::kHardware);
  EXPECT_EQ(detailed.message(), "camera gone");
  const Result<int> carried(detailed);
  EXPECT_EQ(carried.status().detail(), 7);
  EXPECT_EQ(Status::Ok().WithDetail("capture", 7).detail(), 0);
}

TEST(Result, ValueAndErrorAccess) {
  Result<int> good(42);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 42);
  Result<int> bad(Status::Error(ErrorCode::kDegenerateData, "planar"));
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kDegenerateData);
  EXPECT_THROW(bad.value(), InvalidArgument);
  EXPECT_THROW(Result<int>(Status::Ok()), InvalidArgument);
}

TEST(Check, ThrowsWithConditionAndMessage) {
  try {
    SELFCAL_CHECK(1 + 1 == 3, "arithmetic " << 2);
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("1 + 1 == 3"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("arithmetic 2"), std::string::npos);
  }
}

}  // namespace
}  // namespace selfcal

// Fault specs: JSON both ways for every kind, and errors that name the field.
#include "sim/faults/fault_spec.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace px {
namespace {

using ::testing::HasSubstr;

TEST(FaultSpecTest, EveryKindRoundTripsThroughJson) {
  const nlohmann::json plan = nlohmann::json::parse(R"([
    {"kind":"truncate","capture":2,"view":0,"keep":0.6,"seed":1},
    {"kind":"garble","capture":1,"view":3,"bytes":10,"flagged":false,"seed":7},
    {"kind":"drop","capture":0,"view":4,"seed":1},
    {"kind":"reorder","capture":5,"seed":9},
    {"kind":"reformat","capture":1,"view":0,"pixel_format":"NV12","width":64,"height":48,"seed":1},
    {"kind":"stall","capture":3,"seed":1},
    {"kind":"vanish","capture":4,"forever":true,"seed":1}
  ])");
  auto specs = FaultSpecsFromJson(plan);
  ASSERT_TRUE(specs.ok()) << specs.status().ToString();
  ASSERT_EQ(specs->size(), 7u);
  EXPECT_EQ((*specs)[0].kind, FaultKind::kTruncate);
  EXPECT_DOUBLE_EQ((*specs)[0].keep, 0.6);
  EXPECT_FALSE((*specs)[1].flagged);
  EXPECT_EQ((*specs)[1].seed, 7u);
  EXPECT_EQ((*specs)[2].capture, 0);
  EXPECT_EQ((*specs)[4].pixel_format, PixelFormat::kNv12);
  EXPECT_TRUE((*specs)[6].forever);
  EXPECT_EQ(FaultSpecsToJson(*specs), plan);
  EXPECT_EQ(DescribeFault((*specs)[0]), "truncate at capture 2 (keep 0.6, view 0)");
}

TEST(FaultSpecTest, DefaultsFillAbsentFields) {
  auto spec = FaultSpecFromJson(nlohmann::json::parse(R"({"kind":"vanish"})"));
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  EXPECT_EQ(spec->capture, 1);
  EXPECT_FALSE(spec->forever);
}

TEST(FaultSpecTest, ErrorsNameTheField) {
  auto error = [](const std::string& text) {
    auto specs = FaultSpecsFromJson(nlohmann::json::parse(text), "source.faults");
    EXPECT_FALSE(specs.ok()) << text;
    return specs.ok() ? std::string() : specs.status().message();
  };
  EXPECT_THAT(error(R"([{"kind":"melt"}])"), HasSubstr("source.faults[0].kind: 'melt' is not one of truncate"));
  EXPECT_THAT(error(R"([{}])"), HasSubstr("source.faults[0].kind: missing"));
  EXPECT_THAT(error(R"([{"kind":"stall"},{"kind":"truncate","keep":1.5}])"),
              HasSubstr("source.faults[1].keep: 1.5 is not in [0, 1)"));
  EXPECT_THAT(error(R"([{"kind":"stall","keep":0.5}])"),
              HasSubstr("source.faults[0].keep: unknown field for a stall fault (known: kind, capture, seed)"));
  EXPECT_THAT(error(R"([{"kind":"reformat"}])"), HasSubstr("a reformat must change something"));
  EXPECT_THAT(error(R"([{"kind":"reformat","pixel_format":"MJPG"}])"),
              HasSubstr("source.faults[0].pixel_format: 'MJPG' is not one of"));
  EXPECT_THAT(error(R"([{"kind":"drop","capture":-1}])"), HasSubstr("source.faults[0].capture: -1 is negative"));
  EXPECT_THAT(error(R"([{"kind":"garble","bytes":0}])"), HasSubstr("source.faults[0].bytes: 0 is below 1"));
  EXPECT_THAT(error(R"({"kind":"stall"})"), HasSubstr("source.faults: want an array"));
}

}  // namespace
}  // namespace px

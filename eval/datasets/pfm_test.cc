#include "eval/datasets/pfm.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "tests/testing/temp_dir.h"

namespace px::eval {
namespace {

using ::testing::HasSubstr;
using PfmTest = px::testing::TempDirTest;

TEST_F(PfmTest, RoundTripKeepsTopRowFirstAndNonFiniteValues) {
  cv::Mat image(3, 4, CV_32F);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x) image.at<float>(y, x) = static_cast<float>(10 * y + x);
  }
  image.at<float>(1, 2) = std::numeric_limits<float>::infinity();
  ASSERT_TRUE(WritePfm(dir() / "a.pfm", image).ok());
  StatusOr<cv::Mat> read = ReadPfm(dir() / "a.pfm");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->at<float>(0, 3), 3.0f);
  EXPECT_EQ(read->at<float>(2, 0), 20.0f);
  EXPECT_TRUE(std::isinf(read->at<float>(1, 2)));
}

TEST_F(PfmTest, TruncatedAndForeignFilesAreNamed) {
  cv::Mat image(8, 8, CV_32F, cv::Scalar(1));
  ASSERT_TRUE(WritePfm(dir() / "a.pfm", image).ok());
  std::filesystem::resize_file(dir() / "a.pfm", std::filesystem::file_size(dir() / "a.pfm") - 40);
  EXPECT_THAT(ReadPfm(dir() / "a.pfm").status().message(), HasSubstr("a.pfm: truncated"));
  std::ofstream(dir() / "b.pfm") << "P6\n8 8\n255\n";
  EXPECT_THAT(ReadPfm(dir() / "b.pfm").status().message(), HasSubstr("not a PFM file"));
  EXPECT_EQ(ReadPfm(dir() / "missing.pfm").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace px::eval

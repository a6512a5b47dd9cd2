#include "pipeline/calib/matching.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

namespace px::calib {
namespace {

// Unit-length descriptors, as RootSIFT's are.
Features RandomFeatures(int count, uint64_t seed) {
  Features features;
  features.descriptors.create(count, 128, CV_32F);
  cv::RNG rng(seed);
  rng.fill(features.descriptors, cv::RNG::UNIFORM, 0.0, 1.0);
  for (int i = 0; i < count; ++i) cv::normalize(features.descriptors.row(i), features.descriptors.row(i));
  features.keypoints_px.assign(count, Eigen::Vector2d::Zero());
  features.scales_px.assign(count, 1.0f);
  return features;
}

// The definition, pair by pair: each feature of a's nearest and second nearest in b.
std::vector<FeatureMatch> Reference(const Features& a, const Features& b, const MatchOptions& options) {
  std::vector<int> best_of_b(b.size(), -1);
  std::vector<double> best_distance_of_b(b.size(), 1e30);
  std::vector<FeatureMatch> matches;
  std::vector<int> best(a.size());
  std::vector<double> first(a.size(), 1e30), second(a.size(), 1e30);
  for (int i = 0; i < a.size(); ++i) {
    for (int j = 0; j < b.size(); ++j) {
      const double d = cv::norm(a.descriptors.row(i), b.descriptors.row(j), cv::NORM_L2);
      if (d < first[i]) {
        second[i] = first[i];
        first[i] = d;
        best[i] = j;
      } else if (d < second[i]) {
        second[i] = d;
      }
      if (d < best_distance_of_b[j]) {
        best_distance_of_b[j] = d;
        best_of_b[j] = i;
      }
    }
  }
  for (int i = 0; i < a.size(); ++i) {
    if (!(first[i] < options.ratio * second[i])) continue;
    if (options.mutual && best_of_b[best[i]] != i) continue;
    matches.push_back({i, best[i]});
  }
  return matches;
}

TEST(MatchingTest, FloatDescriptorsMatchAsThePairByPairDefinitionDoes) {
  // More rows than one block of the matrix product, so the blocks' hand-over is covered.
  const Features a = RandomFeatures(700, 1);
  Features b = RandomFeatures(300, 2);
  // Half of b are noisy copies of a's features 100..249, in reverse order.
  cv::RNG rng(3);
  for (int k = 0; k < 150; ++k) {
    cv::Mat noise(1, 128, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.01);
    cv::Mat copy = a.descriptors.row(249 - k) + noise;
    copy.copyTo(b.descriptors.row(2 * k));
  }
  for (const bool mutual : {true, false}) {
    MatchOptions options;
    options.mutual = mutual;
    const std::vector<FeatureMatch> matches = MatchAll(a, b, options);
    const std::vector<FeatureMatch> expected = Reference(a, b, options);
    ASSERT_EQ(matches.size(), expected.size()) << "mutual " << mutual;
    for (size_t k = 0; k < matches.size(); ++k) {
      EXPECT_EQ(matches[k].a, expected[k].a);
      EXPECT_EQ(matches[k].b, expected[k].b);
    }
    int copies_found = 0;
    for (const FeatureMatch& m : matches) copies_found += m.b % 2 == 0 && m.b / 2 == 249 - m.a;
    EXPECT_EQ(copies_found, 150) << "every planted copy is found";
  }
}

TEST(MatchingTest, AnEmptySideOrMixedDescriptorsMatchNothing) {
  const Features a = RandomFeatures(10, 1);
  EXPECT_TRUE(MatchAll(a, Features{}, MatchOptions{}).empty());
  Features binary;
  binary.descriptors = cv::Mat::zeros(10, 32, CV_8U);
  binary.keypoints_px.assign(10, Eigen::Vector2d::Zero());
  EXPECT_TRUE(MatchAll(a, binary, MatchOptions{}).empty());
}

}  // namespace
}  // namespace px::calib

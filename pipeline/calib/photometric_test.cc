// Photometric equalisation on synthetic views with known exposure, colour cast and vignetting
// differences: the fitted field undoes them, parallax and a moving subject do not bend it, and
// views of one exposure are left untouched.
#include "pipeline/calib/photometric.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace px::calib {
namespace {

// A scene wider than the views: smooth colour blobs with sharp-edged rectangles over them.
cv::Mat Scene(cv::Size size) {
  cv::Mat noise(size / 8, CV_8UC3), scene;
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 40, 215);
  cv::resize(noise, scene, size, 0, 0, cv::INTER_CUBIC);
  for (int i = 0; i < 40; ++i) {
    const cv::Point corner(rng.uniform(0, size.width - 40), rng.uniform(0, size.height - 40));
    cv::rectangle(scene,
                  cv::Rect(corner, cv::Size(rng.uniform(8, 40), rng.uniform(8, 40))),
                  cv::Scalar(rng.uniform(30, 220), rng.uniform(30, 220), rng.uniform(30, 220)),
                  cv::FILLED);
  }
  return scene;
}

View ViewOf(const cv::Mat& scene, int x, int id) {
  View view;
  view.id = ViewId{id};
  view.image = scene(cv::Rect(x, 20, 480, 360)).clone();
  view.camera = CameraModel::Pinhole(480, 360, 500);
  return view;
}

// `gain` per channel (B, G, R) at the centre, falling to `corner` of it at the corners.
void Expose(View* view, cv::Vec3d gain, double corner) {
  cv::Mat out(view->image.size(), CV_8UC3);
  const double half_w = view->image.cols / 2.0, half_h = view->image.rows / 2.0;
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      const double u = (x + 0.5 - half_w) / half_w, v = (y + 0.5 - half_h) / half_h;
      const double falloff = 1 - (1 - corner) * (u * u + v * v) / 2;
      const cv::Vec3b in = view->image.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) out.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uint8_t>(in[c] * gain[c] * falloff);
    }
  }
  view->image = out;
}

double MeanAbsDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  const cv::Scalar mean = cv::mean(difference);
  return (mean[0] + mean[1] + mean[2]) / 3;
}

TEST(PhotometricTest, ExposureCastAndVignettingOfAShiftedViewAreUndone) {
  const cv::Mat scene = Scene(cv::Size(560, 400));
  std::vector<View> views = {ViewOf(scene, 40, 0), ViewOf(scene, 52, 1)};  // 12 px of parallax
  const cv::Mat truth = views[1].image.clone();
  Expose(&views[1], cv::Vec3d(0.75, 0.65, 0.8), 0.6);
  // A subject that moved between the exposures: a patch the reference does not have.
  cv::rectangle(views[1].image, cv::Rect(300, 200, 70, 90), cv::Scalar(250, 30, 30), cv::FILLED);
  cv::Mat truth_with_subject = truth.clone();
  cv::rectangle(truth_with_subject, cv::Rect(300, 200, 70, 90), cv::Scalar(250, 30, 30), cv::FILLED);
  const double before = MeanAbsDifference(views[1].image, truth_with_subject);

  StatusOr<PhotometricReport> report = EqualisePhotometry(&views, 0, PhotometricOptions{});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::printf("[figures] %s\n", report->Summary().c_str());
  const ViewPhotometry& fitted = report->views[1];
  ASSERT_TRUE(fitted.applied) << fitted.note;
  EXPECT_NEAR(fitted.centre_gain[0], 1 / 0.75, 0.06);
  EXPECT_NEAR(fitted.centre_gain[1], 1 / 0.65, 0.06);
  EXPECT_NEAR(fitted.centre_gain[2], 1 / 0.8, 0.06);
  EXPECT_NEAR(fitted.corner_falloff, 1 / 0.6, 0.15);  // the corners brought up by the lost light
  // Away from the subject (which the field must not absorb) the view is its true self again.
  cv::Mat outside(truth.size(), CV_8U, cv::Scalar(255));
  cv::rectangle(outside, cv::Rect(290, 190, 90, 110), cv::Scalar(0), cv::FILLED);
  cv::Mat difference;
  cv::absdiff(views[1].image, truth_with_subject, difference);
  const cv::Scalar after = cv::mean(difference, outside);
  std::printf("[figures] mean difference from the true colours: %.1f grey levels before, %.1f after\n",
              before,
              (after[0] + after[1] + after[2]) / 3);
  EXPECT_LT((after[0] + after[1] + after[2]) / 3, 4.0);
  EXPECT_GT(before, 25.0);
  EXPECT_LT(fitted.difference_after, 0.3 * fitted.difference_before);
}

// A red subject bright enough to clip the reference's red channel (a petal in the sun) fills a
// third of the view: its pixels say nothing of the exposure and must not bend the field (tilt it
// towards the subject, or draw a vignette) that equalises the rest of the view.
TEST(PhotometricTest, ClippedHighlightsDoNotBendTheField) {
  cv::Mat scene = Scene(cv::Size(560, 400));
  const cv::Rect subject(40, 0, 200, 400);
  std::vector<cv::Mat> channels;
  cv::split(scene(subject), channels);
  channels[0] *= 0.5;
  channels[1] *= 0.5;
  channels[2] = 200 + channels[2] * 0.2;  // 208 to 243: clipped from a gain of 1.05 on
  cv::merge(channels, scene(subject));
  constexpr double kGain = 1.3;
  std::vector<View> views = {ViewOf(scene, 40, 0), ViewOf(scene, 52, 1)};
  Expose(&views[0], cv::Vec3d::all(kGain), 1.0);
  cv::Mat truth;
  views[1].image.convertTo(truth, CV_8UC3, kGain);  // what the reference's exposure made of it

  StatusOr<PhotometricReport> report = EqualisePhotometry(&views, 0, PhotometricOptions{});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::printf("[figures] %s\n", report->Summary().c_str());
  const ViewPhotometry& fitted = report->views[1];
  ASSERT_TRUE(fitted.applied) << fitted.note;
  EXPECT_NEAR(fitted.centre_gain[0], kGain, 0.06);
  EXPECT_NEAR(fitted.centre_gain[1], kGain, 0.06);
  EXPECT_NEAR(fitted.centre_gain[2], kGain, 0.06);
  EXPECT_NEAR(fitted.corner_falloff, 1.0, 0.08);
  // Right of the subject, where nothing clips, the view is as the reference's exposure saw it.
  const cv::Rect clear(220, 0, 260, 360);
  const double after = MeanAbsDifference(views[1].image(clear), truth(clear));
  std::printf("[figures] clipped subject: gain %.2f/%.2f/%.2f, corner %.2f, %.1f levels from the truth beside it\n",
              fitted.centre_gain[2],
              fitted.centre_gain[1],
              fitted.centre_gain[0],
              fitted.corner_falloff,
              after);
  EXPECT_LT(after, 3.0);
}

TEST(PhotometricTest, ViewsOfOneExposureAreLeftAsTheyAre) {
  const cv::Mat scene = Scene(cv::Size(560, 400));
  std::vector<View> views = {ViewOf(scene, 40, 0), ViewOf(scene, 60, 1), ViewOf(scene, 70, 2)};
  const cv::Mat first = views[1].image.clone(), second = views[2].image.clone();
  StatusOr<PhotometricReport> report = EqualisePhotometry(&views, 0, PhotometricOptions{});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  std::printf("[figures] %s\n", report->Summary().c_str());
  EXPECT_FALSE(report->views[1].applied);
  EXPECT_FALSE(report->views[2].applied);
  EXPECT_EQ(MeanAbsDifference(views[1].image, first), 0.0);
  EXPECT_EQ(MeanAbsDifference(views[2].image, second), 0.0);
}

TEST(PhotometricTest, BadInputIsRefusedOrLeftAlone) {
  std::vector<View> views(2);
  views[0].image = cv::Mat(100, 100, CV_8UC3, cv::Scalar::all(0));
  views[1].image = cv::Mat(100, 100, CV_8UC1, cv::Scalar::all(0));
  EXPECT_FALSE(EqualisePhotometry(&views, 0, PhotometricOptions{}).ok());
  EXPECT_FALSE(EqualisePhotometry(&views, 2, PhotometricOptions{}).ok());
  views[0] = ViewOf(Scene(cv::Size(560, 400)), 40, 0);
  views[1].image = cv::Mat(360, 480, CV_8UC3, cv::Scalar::all(0));  // black: nothing to compare
  StatusOr<PhotometricReport> report = EqualisePhotometry(&views, 0, PhotometricOptions{});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_FALSE(report->views[1].applied);
  EXPECT_NE(report->views[1].note.find("too few"), std::string::npos) << report->views[1].note;
  PhotometricOptions bad;
  bad.max_gain = 0.5;
  EXPECT_NE(EqualisePhotometry(&views, 0, bad).status().message().find("max_gain"), std::string::npos);
}

}  // namespace
}  // namespace px::calib

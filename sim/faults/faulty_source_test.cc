// Each fault, injected around a real source: the simulated lattice camera (sim/synthetic) and a
// small image-set source defined here (no image-set camera exists in the tree yet).
#include "sim/faults/faulty_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/faults/frame_damage.h"
#include "sim/synthetic/synthetic_source.h"

namespace px {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

// Five 32x24 BGR images per frame set, image k a gradient offset by k, sequences counting up.
class ImageSetSource final : public FrameSource {
 public:
  std::string_view Name() const override { return "images"; }
  SourceDescription Describe() const override { return {"test:images", FrameSetKind::kImageSet, std::nullopt}; }
  StatusOr<ConfigureResult> Configure(const SourceConfig&, SourceConfig* granted) override {
    *granted = {PixelFormat::kBgr888, 32, 24, 5};
    return ConfigureResult::kValid;
  }
  StatusOr<FrameSet> Next(milliseconds) override {
    FrameSet set;
    set.kind = FrameSetKind::kImageSet;
    set.capture_id = ++captures;
    for (int k = 0; k < 5; ++k) {
      cv::Mat bgr(24, 32, CV_8UC3);
      for (int y = 0; y < 24; ++y) {
        for (int x = 0; x < 32; ++x) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 7, y * 9, 40 * k);
      }
      Frame frame;
      frame.image = FromBgr(bgr, PixelFormat::kBgr888).value();
      frame.sequence = ++sequence;
      set.frames.push_back(std::move(frame));
    }
    return set;
  }
  void Stop() override { stops++; }

  uint64_t captures = 0;
  uint64_t sequence = 0;
  int stops = 0;
};

// The simulated Pop9 at 64x48 tiles: a real lattice camera, quick to render.
std::unique_ptr<FrameSource> SmallLattice(PixelFormat format = PixelFormat::kRgb888) {
  SyntheticSourceOptions options;
  options.camera.tile_width = 64;
  options.camera.tile_height = 48;
  options.camera.focal_px = 56;
  options.camera.gap_px = 8;
  options.camera.pixel_format = format;
  options.camera.noise_sigma = 2.0;  // every tile has texture, so a blank one stands out
  auto source = MakeSyntheticSource(options);
  EXPECT_TRUE(source.ok()) << source.status().ToString();
  return std::move(source).value();
}

std::vector<FaultSpec> Plan(const std::string& text) { return FaultSpecsFromJson(nlohmann::json::parse(text)).value(); }

struct Wrapped {
  std::unique_ptr<FrameSource> source;
  SourceConfig granted;
};

Wrapped Wrap(std::unique_ptr<FrameSource> inner, const std::string& plan) {
  auto wrapped = MakeFaultySource(std::move(inner), Plan(plan));
  EXPECT_TRUE(wrapped.ok()) << wrapped.status().ToString();
  Wrapped result{std::move(wrapped).value(), {}};
  EXPECT_TRUE(result.source->Configure({}, &result.granted).ok());
  return result;
}

TEST(FaultySourceTest, TruncateShortensTheBufferAtTheNamedCaptureOnly) {
  Wrapped w = Wrap(SmallLattice(), R"([{"kind":"truncate","capture":2,"keep":0.25}])");
  FrameSet first = w.source->Next(milliseconds(1000)).value();
  EXPECT_TRUE(CheckFrameSet(w.granted, &first).ok());
  const size_t full = first.frames[0].image.bytes.size();
  FrameSet second = w.source->Next(milliseconds(1000)).value();
  EXPECT_EQ(second.frames[0].image.bytes.size(), full / 4);
  EXPECT_EQ(second.frames[0].status, FrameStatus::kCorrupt);
  EXPECT_THAT(second.frames[0].status_detail, HasSubstr("truncated: " + std::to_string(full / 4) + " of"));
  EXPECT_FALSE(CheckFrameSet(w.granted, &second).ok());  // nothing usable in a one-frame capture
  FrameSet third = w.source->Next(milliseconds(1000)).value();
  EXPECT_EQ(third.frames[0].image.bytes.size(), full);
}

TEST(FaultySourceTest, GarbleChangesBytesDeterministicallyAndFlagsWhenAsked) {
  Wrapped flagged = Wrap(SmallLattice(), R"([{"kind":"garble","bytes":50,"seed":3}])");
  Wrapped again = Wrap(SmallLattice(), R"([{"kind":"garble","bytes":50,"seed":3}])");
  Wrapped silent = Wrap(SmallLattice(), R"([{"kind":"garble","bytes":50,"seed":3,"flagged":false}])");
  FrameSet a = flagged.source->Next(milliseconds(1000)).value();
  FrameSet b = again.source->Next(milliseconds(1000)).value();
  FrameSet c = silent.source->Next(milliseconds(1000)).value();
  EXPECT_EQ(a.frames[0].status, FrameStatus::kCorrupt);
  EXPECT_THAT(a.frames[0].status_detail, HasSubstr("garbled"));
  EXPECT_EQ(c.frames[0].status, FrameStatus::kOk);              // silent damage: the camera cannot tell
  EXPECT_EQ(a.frames[0].image.bytes, b.frames[0].image.bytes);  // same seed, same damage
  EXPECT_EQ(a.frames[0].image.bytes, c.frames[0].image.bytes);
  // Compare with an undamaged capture of the same (deterministic) sensor.
  Wrapped clean = Wrap(SmallLattice(), "[]");
  FrameSet d = clean.source->Next(milliseconds(1000)).value();
  ASSERT_EQ(a.frames[0].image.bytes.size(), d.frames[0].image.bytes.size());
  int changed = 0;
  for (size_t i = 0; i < d.frames[0].image.bytes.size(); ++i)
    changed += a.frames[0].image.bytes[i] != d.frames[0].image.bytes[i];
  EXPECT_GT(changed, 40);  // 50 draws; a repeated offset may cancel out, seldom
  EXPECT_LE(changed, 50);
}

TEST(FaultySourceTest, DropOnALatticeBlanksOneTileLikeACoveredLens) {
  Wrapped w = Wrap(SmallLattice(), R"([{"kind":"drop","view":4}])");
  FrameSet frames = w.source->Next(milliseconds(1000)).value();
  ASSERT_TRUE(CheckFrameSet(w.granted, &frames).ok());
  EXPECT_EQ(frames.frames[0].status, FrameStatus::kOk);
  const LatticeLayout lattice = w.source->Describe().rig->lattice;
  cv::Mat bgr = ToBgr(frames.frames[0].image).value();
  for (int t = 0; t < lattice.NumViews(); ++t) {
    cv::Scalar mean, stddev;
    cv::meanStdDev(bgr(lattice.tiles[t].rect), mean, stddev);
    if (t == 4) {
      EXPECT_EQ(stddev[0] + stddev[1] + stddev[2], 0) << "tile 4 is flat";
    } else {
      EXPECT_GT(stddev[0], 1.0) << "tile " << t << " still shows the scene";
    }
  }
}

TEST(FaultySourceTest, BlankRectIsFlatInEveryPixelFormat) {
  cv::Mat bgr(48, 64, CV_8UC3);
  cv::randu(bgr, 0, 255);
  const cv::Rect rect(10, 8, 30, 20);
  for (PixelFormat format : {PixelFormat::kRgb888,
                             PixelFormat::kBgr888,
                             PixelFormat::kGray8,
                             PixelFormat::kYuyv,
                             PixelFormat::kNv12,
                             PixelFormat::kBayerRggb8}) {
    RawImage raw = FromBgr(bgr, format).value();
    ASSERT_TRUE(faults::BlankRect(rect, &raw).ok()) << PixelFormatName(format);
    cv::Mat back = ToBgr(raw).value();
    cv::Scalar mean, stddev;
    // Demosaicing and chroma subsampling reach one or two pixels over the rect's edge.
    cv::meanStdDev(back(cv::Rect(rect.x + 2, rect.y + 2, rect.width - 4, rect.height - 4)), mean, stddev);
    EXPECT_LT(stddev[0] + stddev[1] + stddev[2], 0.5) << PixelFormatName(format);
    EXPECT_LT(mean[1], 30) << PixelFormatName(format);
    cv::meanStdDev(back(cv::Rect(44, 0, 20, 48)), mean, stddev);
    EXPECT_GT(stddev[1], 30) << PixelFormatName(format) << ": outside the rect is untouched";
  }
  RawImage raw = FromBgr(bgr, PixelFormat::kRgb888).value();
  EXPECT_THAT(faults::BlankRect(cv::Rect(60, 0, 10, 10), &raw).message(), HasSubstr("is not inside the 64x48 frame"));
}

TEST(FaultySourceTest, DropOnAnImageSetLosesTheImage) {
  Wrapped w = Wrap(std::make_unique<ImageSetSource>(), R"([{"kind":"drop","view":2}])");
  FrameSet frames = w.source->Next(milliseconds(1000)).value();
  ASSERT_EQ(frames.frames.size(), 5u);
  EXPECT_EQ(frames.frames[2].status, FrameStatus::kDropped);
  EXPECT_TRUE(frames.frames[2].image.bytes.empty());
  EXPECT_EQ(frames.NumUsableFrames(), 4);
  EXPECT_TRUE(CheckFrameSet(w.granted, &frames).ok());
}

TEST(FaultySourceTest, ReorderPermutesImagesWhichKeepTheirSequence) {
  Wrapped w = Wrap(std::make_unique<ImageSetSource>(), R"([{"kind":"reorder","seed":5}])");
  FrameSet frames = w.source->Next(milliseconds(1000)).value();
  std::vector<uint64_t> sequences;
  for (const Frame& frame : frames.frames) {
    sequences.push_back(frame.sequence);
    // Image k's blue channel is 40 * k: the content travelled with its sequence number.
    EXPECT_EQ(ToBgr(frame.image).value().at<cv::Vec3b>(0, 0)[2], 40 * (frame.sequence - 1));
  }
  EXPECT_FALSE(std::is_sorted(sequences.begin(), sequences.end()));
  std::sort(sequences.begin(), sequences.end());
  EXPECT_EQ(sequences, (std::vector<uint64_t>{1, 2, 3, 4, 5}));
}

TEST(FaultySourceTest, ReformatIsCaughtByTheFrameCheck) {
  Wrapped w = Wrap(SmallLattice(), R"([{"kind":"reformat","pixel_format":"NV12"},
                                       {"kind":"reformat","capture":2,"width":100,"height":60}])");
  FrameSet first = w.source->Next(milliseconds(1000)).value();
  EXPECT_EQ(first.frames[0].image.format, PixelFormat::kNv12);
  EXPECT_TRUE(first.frames[0].image.Validate().ok());
  EXPECT_FALSE(CheckFrameSet(w.granted, &first).ok());
  EXPECT_EQ(first.frames[0].status, FrameStatus::kWrongFormat);
  EXPECT_THAT(first.frames[0].status_detail, HasSubstr("NV12, want"));
  FrameSet second = w.source->Next(milliseconds(1000)).value();
  EXPECT_EQ(second.frames[0].image.width, 100);
  EXPECT_FALSE(CheckFrameSet(w.granted, &second).ok());
  EXPECT_THAT(second.frames[0].status_detail, HasSubstr("got 100x60 BGR888, want 224x176"));
}

TEST(FaultySourceTest, StallWaitsTheWholeTimeoutThenDeadlineExceeded) {
  Wrapped w = Wrap(SmallLattice(), R"([{"kind":"stall","capture":1}])");
  const auto start = std::chrono::steady_clock::now();
  auto stalled = w.source->Next(milliseconds(150));
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(stalled.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_THAT(stalled.status().message(), HasSubstr("no frame set within 150 ms"));
  EXPECT_GE(waited, milliseconds(150));
  EXPECT_TRUE(w.source->Next(milliseconds(150)).ok());  // the camera answers again
}

TEST(FaultySourceTest, VanishStaysGoneUntilConfiguredAgain) {
  Wrapped w = Wrap(std::make_unique<ImageSetSource>(), R"([{"kind":"vanish","capture":2}])");
  EXPECT_TRUE(w.source->Next(milliseconds(100)).ok());
  auto gone = w.source->Next(milliseconds(100));
  EXPECT_EQ(gone.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(gone.status().message(), HasSubstr("camera disconnected during capture 2"));
  EXPECT_EQ(w.source->Next(milliseconds(100)).status().code(), StatusCode::kUnavailable);
  SourceConfig granted;
  ASSERT_TRUE(w.source->Configure({}, &granted).ok());
  EXPECT_TRUE(w.source->Next(milliseconds(100)).ok());
}

TEST(FaultySourceTest, VanishForeverRefusesConfigureToo) {
  Wrapped w = Wrap(std::make_unique<ImageSetSource>(), R"([{"kind":"vanish","capture":1,"forever":true}])");
  EXPECT_EQ(w.source->Next(milliseconds(100)).status().code(), StatusCode::kUnavailable);
  SourceConfig granted;
  auto configured = w.source->Configure({}, &granted);
  EXPECT_EQ(configured.status().code(), StatusCode::kUnavailable);
  EXPECT_THAT(configured.status().message(), HasSubstr("gone for good"));
  EXPECT_EQ(w.source->Next(milliseconds(100)).status().code(), StatusCode::kUnavailable);
}

TEST(FaultySourceTest, PlanIsCheckedAgainstTheSource) {
  auto error = [](std::unique_ptr<FrameSource> inner, const std::string& plan) {
    auto wrapped = MakeFaultySource(std::move(inner), Plan(plan), "source.faults");
    return wrapped.ok() ? std::string("ok") : wrapped.status().message();
  };
  EXPECT_THAT(error(SmallLattice(), R"([{"kind":"reorder"}])"),
              HasSubstr("source.faults[0]: reorder needs an image set; sim:sim-pop9 delivers lattice frames"));
  EXPECT_THAT(error(SmallLattice(), R"([{"kind":"stall"},{"kind":"drop","view":9}])"),
              HasSubstr("source.faults[1].view: 9 is not a tile of the 3x3 lattice"));
  EXPECT_THAT(error(SmallLattice(), R"([{"kind":"truncate","view":2}])"),
              HasSubstr("a lattice capture is one sensor frame"));
  EXPECT_EQ(error(std::make_unique<ImageSetSource>(), R"([{"kind":"reorder"}])"), "ok");
  // An image index beyond the capture is reported at that capture, naming the fault.
  Wrapped w = Wrap(std::make_unique<ImageSetSource>(), R"([{"kind":"drop","view":7}])");
  EXPECT_THAT(w.source->Next(milliseconds(100)).status().message(),
              HasSubstr("faults[0]: view 7: the capture holds 5 frame(s)"));
}

}  // namespace
}  // namespace px

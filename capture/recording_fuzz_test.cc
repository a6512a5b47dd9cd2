// Robustness: 200 seeded random mutations of a valid manifest. ReadRecording must never crash,
// must name the manifest or a frame file when it refuses, and must never accept a manifest
// whose frames no longer match the pictures that were recorded.
#include <gtest/gtest.h>

#include <array>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "capture/recording.h"
#include "capture/recording_test_util.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

enum Mutation { kTruncate, kFlipByte, kDeleteKey, kChangeType, kChangeNumber, kSwapString, kNumMutations };
constexpr std::array<const char*, kNumMutations> kMutationNames = {
    "truncate", "flip byte", "delete key", "change type", "change number", "swap string"};

// Every value's JSON pointer below the root, parents before children.
void CollectPointers(const Json& j, const Json::json_pointer& at, std::vector<Json::json_pointer>* out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      out->push_back(at / it.key());
      CollectPointers(it.value(), at / it.key(), out);
    }
  } else if (j.is_array()) {
    for (size_t i = 0; i < j.size(); ++i) {
      out->push_back(at / i);
      CollectPointers(j[i], at / i, out);
    }
  }
}

template <typename T>
const T& Pick(const std::vector<T>& items, std::mt19937_64& rng) {
  return items[std::uniform_int_distribution<size_t>(0, items.size() - 1)(rng)];
}

std::string Mutate(const std::string& text, Mutation mutation, std::mt19937_64& rng) {
  if (mutation == kTruncate) {
    // Anywhere before the closing brace, so the document is always cut.
    return text.substr(0, std::uniform_int_distribution<size_t>(0, text.rfind('}') - 1)(rng));
  }
  if (mutation == kFlipByte) {
    std::string flipped = text;
    const size_t at = std::uniform_int_distribution<size_t>(0, text.size() - 1)(rng);
    flipped[at] = static_cast<char>(flipped[at] ^ std::uniform_int_distribution<int>(1, 255)(rng));
    return flipped;
  }
  Json j = Json::parse(text);
  std::vector<Json::json_pointer> pointers;
  CollectPointers(j, Json::json_pointer(), &pointers);
  if (mutation == kDeleteKey) {
    std::vector<Json::json_pointer> members;
    for (const auto& p : pointers) {
      if (j[p.parent_pointer()].is_object()) members.push_back(p);
    }
    const Json::json_pointer& victim = Pick(members, rng);
    j[victim.parent_pointer()].erase(victim.back());
  } else if (mutation == kChangeType) {
    const std::vector<Json> replacements = {"x", 1.5, 7, -3, nullptr, Json::array(), Json::object(), true, ""};
    const Json::json_pointer& p = Pick(pointers, rng);
    Json replacement = Pick(replacements, rng);
    if (replacement.type() == j[p].type()) replacement = Json::array({replacement});
    j[p] = replacement;
  } else if (mutation == kChangeNumber) {
    std::vector<Json::json_pointer> numbers;
    for (const auto& p : pointers) {
      if (j[p].is_number()) numbers.push_back(p);
    }
    const Json::json_pointer& p = Pick(numbers, rng);
    const double value = j[p].get<double>();
    const std::vector<Json> changes = {value + 1, value - 1, value * 2, 0, -value, 1e300};
    Json changed = Pick(changes, rng);
    if (j[p].is_number_integer() && changed.is_number_float() && changed.get<double>() < 9e18 &&
        changed.get<double>() > -9e18) {
      changed = static_cast<int64_t>(changed.get<double>());
    }
    j[p] = changed;
  } else {
    std::vector<Json::json_pointer> strings;
    for (const auto& p : pointers) {
      if (j[p].is_string()) strings.push_back(p);
    }
    const std::vector<std::string> vocabulary = {"RGB888",
                                                 "BGR888",
                                                 "GRAY8",
                                                 "YUYV",
                                                 "NV12",
                                                 "SRGGB8",
                                                 "ok",
                                                 "corrupt",
                                                 "dropped",
                                                 "wrong_format",
                                                 "frame_0000.png",
                                                 "frame_0001.raw",
                                                 "frame_0002.png",
                                                 "image_set",
                                                 "lattice_frame",
                                                 "manifest.json"};
    j[Pick(strings, rng)] = Pick(vocabulary, rng);
  }
  return j.dump(2);
}

// The picture a frame holds, however its bytes are ordered (BGR888 and RGB888 of the same
// PNG are the same picture).
bool SamePicture(const Frame& expected, const Frame& actual) {
  if (expected.image.width != actual.image.width || expected.image.height != actual.image.height) return false;
  if (expected.image.format == actual.image.format) return expected.image.bytes == actual.image.bytes;
  StatusOr<cv::Mat> a = ToBgr(expected.image);
  StatusOr<cv::Mat> b = ToBgr(actual.image);
  return a.ok() && b.ok() && cv::norm(*a, *b, cv::NORM_INF) == 0;
}

TEST(RecordingFuzzTest, RandomManifestDamageIsRefusedOrHarmless) {
  capture::testing::ScratchDir scratch;
  const fs::path dir = scratch.path() / "set";
  // PNG, raw and dropped frames, with a rig: every branch of the reader has something to check.
  Recording recording = capture::testing::ImageSetRecording(3, PixelFormat::kBgr888);
  recording.frames.frames[1].image = capture::testing::TestImage(PixelFormat::kYuyv, 64, 48, 5);
  recording.frames.frames[2].image.bytes.clear();
  recording.frames.frames[2].status = FrameStatus::kDropped;
  ASSERT_TRUE(WriteRecording(dir, recording).ok());
  const std::string original = capture::testing::ReadText(dir / "manifest.json");

  std::mt19937_64 rng(20250301);  // fixed: the same 200 mutations on every run
  std::array<int, kNumMutations> tried{}, refused{};
  for (int i = 0; i < 200; ++i) {
    const auto mutation = static_cast<Mutation>(i % kNumMutations);
    const std::string damaged = Mutate(original, mutation, rng);
    capture::testing::WriteText(dir / "manifest.json", damaged);
    SCOPED_TRACE("mutation " + std::to_string(i) + " (" + kMutationNames[mutation] + "):\n" + damaged);
    ++tried[mutation];

    StatusOr<Recording> read = ReadRecording(dir);
    if (!read.ok()) {
      ++refused[mutation];
      EXPECT_NE(read.status().message().find(dir.string()), std::string::npos) << read.status().ToString();
      continue;
    }
    EXPECT_NE(mutation, kTruncate) << "accepted a truncated manifest";
    ASSERT_EQ(read->frames.frames.size(), recording.frames.frames.size());
    for (size_t f = 0; f < recording.frames.frames.size(); ++f) {
      EXPECT_TRUE(SamePicture(recording.frames.frames[f], read->frames.frames[f]))
          << "frame " << f << " accepted with a different picture";
    }
  }
  for (int m = 0; m < kNumMutations; ++m) {
    std::cout << kMutationNames[m] << ": " << refused[m] << " of " << tried[m] << " refused\n";
    EXPECT_GT(refused[m], 0) << kMutationNames[m] << " never caught anything: is the mutation working?";
  }
  EXPECT_EQ(refused[kTruncate], tried[kTruncate]);
}

}  // namespace
}  // namespace px

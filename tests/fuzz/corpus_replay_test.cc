// Replays every kept fuzz corpus file (tests/fuzz/corpus/<target>/) through the same entry
// points the libFuzzer targets use, with the normal compiler: CI checks that no input a fuzzer
// found (or was seeded with) crashes, hangs or throws, without needing clang. The hand-made
// seeds are checked too: the valid ones must be accepted (else the fuzzer starts from nothing)
// and the tricks refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <vector>

#include "tests/fuzz/fuzz_entry_points.h"

namespace px::fuzz {
namespace {

namespace fs = std::filesystem;

// file name -> whether the entry point accepted it.
std::map<std::string, bool> ReplayCorpus(const std::string& target,
                                         const std::function<bool(const uint8_t*, size_t)>& entry) {
  const fs::path dir = fs::path(PX_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / target;
  std::map<std::string, bool> accepted;
  for (const auto& file : fs::directory_iterator(dir)) {
    if (!file.is_regular_file()) continue;
    std::ifstream in(file.path(), std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    SCOPED_TRACE(file.path().string());
    bool ok = false;
    EXPECT_NO_THROW(ok = entry(bytes.data(), bytes.size()));
    accepted[file.path().filename().string()] = ok;
  }
  std::cout << target << ": " << accepted.size() << " corpus file(s) replayed\n";
  EXPECT_FALSE(accepted.empty()) << dir;
  return accepted;
}

TEST(CorpusReplayTest, ControlRequest) {
  auto accepted =
      ReplayCorpus("control_request", [](const uint8_t* d, size_t n) { return FuzzControlRequest(d, n).ok(); });
  for (const char* seed : {"capture", "status", "list", "wait", "fetch_inline", "set_move", "cancel", "quit_drain"}) {
    EXPECT_TRUE(accepted[seed]) << seed;
  }
  for (const char* seed : {"path_trick", "unknown_field", "malformed", "not_object", "bad_utf8", "nested"}) {
    EXPECT_FALSE(accepted[seed]) << seed;
  }
}

TEST(CorpusReplayTest, Recording) {
  auto accepted = ReplayCorpus("recording", [](const uint8_t* d, size_t n) { return FuzzRecording(d, n).ok(); });
  for (const char* seed : {"yuyv_ok", "truncated_corrupt", "dropped_and_nv12", "srggb8", "gray_png", "rgb_png"}) {
    EXPECT_TRUE(accepted[seed]) << seed;
  }
  EXPECT_FALSE(accepted["bad_sha"]);
  EXPECT_FALSE(accepted["not_json"]);
}

TEST(CorpusReplayTest, Ptp) {
  auto accepted = ReplayCorpus("ptp", [](const uint8_t* d, size_t n) { return FuzzPtp(d, n) > 0; });
  for (const char* seed : {"open_session",
                           "response_ok",
                           "event_object_added",
                           "device_info",
                           "data_device_info",
                           "object_info",
                           "data_object_info"}) {
    EXPECT_TRUE(accepted[seed]) << seed;
  }
  EXPECT_FALSE(accepted["short_header"]);
  EXPECT_FALSE(accepted["length_lies"]);
}

TEST(CorpusReplayTest, Photo) {
  ReplayCorpus("photo", [](const uint8_t* d, size_t n) { return FuzzPhoto(d, n) > 0; });
  const auto decodes = [](const std::string& seed) {
    std::ifstream in(fs::path(PX_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "photo" / seed, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return FuzzPhoto(bytes.data(), bytes.size());
  };
  for (const char* seed : {"jpeg_ok", "png_ok", "gif_ok", "webp_ok_anim"}) EXPECT_GE(decodes(seed), 1) << seed;
  EXPECT_EQ(decodes("mpo_ok"), 2);  // its first image as a JPEG, and both through the MP index
  EXPECT_LT(decodes("mpo_index_past_end"), 2);
  for (const char* seed :
       {"png_claims_40000x40000", "png_claims_4000x3000_short_data", "not_an_image", "gif_claims_65535x65535"}) {
    EXPECT_EQ(decodes(seed), 0) << seed;
  }
}

}  // namespace
}  // namespace px::fuzz

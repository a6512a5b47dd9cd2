// The parallaxd executable itself: --print-config round trip, flag errors, and one press on
// stdin ending in a `clip: <path>` line on stdout.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <stdio.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "device/config.h"
#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct RunResult {
  int exit_code = -1;
  std::string out;
};

// Runs a shell command line (stdout captured; stderr to a file in `dir`) and waits for it.
RunResult RunShell(const std::string& command) {
  RunResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.out.append(buffer, n);
  int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::string ReadLog(const fs::path& path) {
  auto text = ReadFileToString(path);
  return text.ok() ? *text : "";
}

std::string Parallaxd() { return std::string(PX_BINARY_DIR) + "/parallaxd"; }

using ParallaxdTest = px::testing::TempDirTest;

TEST_F(ParallaxdTest, PrintConfigShowsEffectiveValuesAndParsesBack) {
  const fs::path config_file = dir() / "c.json";
  ASSERT_TRUE(
      WriteFileAtomically(config_file, R"({"clip": {"fps": 12}, "source": {"sim": {"tile_width": 160}}})").ok());
  RunResult run = RunShell("PARALLAX_CONFIG= " + Parallaxd() + " --config " + config_file.string() +
                           " --root /data/override --print-config 2>" + (dir() / "err").string());
  ASSERT_EQ(run.exit_code, 0) << ReadLog(dir() / "err");
  nlohmann::json printed = nlohmann::json::parse(run.out);
  auto parsed = DaemonConfigFromJson(printed);
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  EXPECT_EQ(parsed->clip.fps, 12.0);                  // from the file
  EXPECT_EQ(parsed->storage.root, "/data/override");  // the flag wins over the file
  EXPECT_EQ(parsed->source.sim.tile_width, 160);
  EXPECT_EQ(parsed->clip.crf, DaemonConfig().clip.crf);  // untouched default
  EXPECT_EQ(DaemonConfigToJson(*parsed), printed);

  // $PARALLAX_CONFIG is used when --config is absent.
  RunResult from_env = RunShell("PARALLAX_CONFIG=" + config_file.string() + " " + Parallaxd() + " --print-config");
  ASSERT_EQ(from_env.exit_code, 0);
  EXPECT_EQ(nlohmann::json::parse(from_env.out)["clip"]["fps"], 12.0);
}

TEST_F(ParallaxdTest, BadConfigExitsWithTheFieldNamed) {
  const fs::path config_file = dir() / "bad.json";
  ASSERT_TRUE(WriteFileAtomically(config_file, R"({"clip": {"fsp": 12}})").ok());
  RunResult run = RunShell(Parallaxd() + " --config " + config_file.string() + " --print-config 2>&1");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.out, HasSubstr("clip.fsp: unknown field"));
}

TEST_F(ParallaxdTest, OnePressOnStdinPrintsTheClipPathAndExits) {
  const fs::path config_file = dir() / "small.json";
  nlohmann::json config = {
      {"storage", {{"root", (dir() / "store").string()}, {"min_free_mb", 1}}},
      {"control", {{"socket", ""}}},
      {"source", {{"sim", {{"tile_width", 160}, {"tile_height", 120}}}}},
      {"clip", {{"duration_s", 0.5}, {"fps", 10}, {"preset", "ultrafast"}}},
  };
  ASSERT_TRUE(WriteFileAtomically(config_file, config.dump()).ok());
  RunResult run = RunShell("printf 'press\\n' | " + Parallaxd() + " --config " + config_file.string() +
                           " --stdin-trigger 2>" + (dir() / "err").string());
  const std::string log = ReadLog(dir() / "err");
  ASSERT_EQ(run.exit_code, 0) << log;
  const fs::path clip = dir() / "store" / "clips" / "000001.mp4";
  EXPECT_EQ(run.out, "clip: " + clip.string() + "\n") << log;
  EXPECT_TRUE(fs::exists(clip));
  EXPECT_THAT(log, HasSubstr("job 000001: saved capture to"));
}

}  // namespace
}  // namespace px::device

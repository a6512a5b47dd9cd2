// The owner's settings for the next presses: validated field by field, changed in part, applied
// over the config's clip options, and kept in the store across restarts.
#include "device/press_settings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "device/clip_job.h"
#include "pipeline/clip/clip_writer.h"
#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using PressSettingsFileTest = px::testing::TempDirTest;

std::string ErrorOf(const nlohmann::json& changes) {
  StatusOr<PressSettings> updated = UpdatedPressSettings(PressSettings{}, changes);
  return updated.ok() ? "OK" : updated.status().message();
}

TEST(PressSettingsTest, EachBadFieldIsNamedWithWhatItMayBe) {
  EXPECT_THAT(ErrorOf({{"move", "barrel_roll"}}), HasSubstr("move: 'barrel_roll' is not one of auto,"));
  EXPECT_THAT(ErrorOf({{"effect", "sepia"}}), HasSubstr("effect: 'sepia' is not one of auto, none, dof_change"));
  EXPECT_EQ(ErrorOf({{"format", "avi"}}), "format: 'avi' is not one of mp4, gif, webp, png");
  EXPECT_THAT(ErrorOf({{"size", "huge"}}), HasSubstr("size: 'huge' is not WxH (e.g. 1920x1080) or source"));
  EXPECT_THAT(ErrorOf({{"size", "16:9"}}), HasSubstr("size: '16:9' is not WxH"));
  EXPECT_THAT(ErrorOf({{"size", "8x8"}}), HasSubstr("size: "));  // WxH, but too small: says why
  EXPECT_THAT(ErrorOf({{"size", "8x8"}}), Not(HasSubstr("is not WxH")));
  EXPECT_THAT(ErrorOf({{"size", "99999999999x1"}}), HasSubstr("want WIDTHxHEIGHT"));  // no int overflow
  EXPECT_THAT(ErrorOf({{"size", "1080x1920 "}}), HasSubstr("want WIDTHxHEIGHT"));
  EXPECT_THAT(ErrorOf({{"format", 3}}), HasSubstr("format: want a string or null, got number"));
  EXPECT_THAT(ErrorOf({{"fps", "60"}}), HasSubstr("settings: unknown field 'fps'"));
  EXPECT_THAT(ErrorOf(nlohmann::json::array()), HasSubstr("settings: want an object"));
  EXPECT_EQ(ErrorOf({{"move", "dolly_in"}, {"effect", "focus_pull"}, {"format", "webp"}, {"size", "1080x1920"}}), "OK");
  EXPECT_EQ(ErrorOf({{"size", "source"}}), "OK");
}

TEST(PressSettingsTest, AChangeReplacesOnlyTheFieldsItHoldsAndNullGoesBackToTheConfig) {
  PressSettings now{"dolly_in", "saturation", "gif", "1080x1080"};
  StatusOr<PressSettings> changed = UpdatedPressSettings(now, {{"format", "webp"}, {"size", nullptr}});
  ASSERT_TRUE(changed.ok()) << changed.status().ToString();
  EXPECT_EQ(changed->move, "dolly_in");
  EXPECT_EQ(changed->effect, "saturation");
  EXPECT_EQ(changed->format, "webp");
  EXPECT_EQ(changed->size, "");
  EXPECT_EQ(PressSettingsToJson(*changed)["size"], nullptr);
  // A refused change leaves nothing half applied (the caller keeps `now`).
  EXPECT_FALSE(UpdatedPressSettings(now, {{"format", "webp"}, {"effect", "sepia"}}).ok());
}

TEST(PressSettingsTest, AppliedOverTheConfigsClipOptions) {
  ClipJobOptions options;
  options.pipeline.direct.move = "establishing_dolly";
  options.pipeline.direct.output.height = 480;
  ASSERT_TRUE(ApplyPressSettings(PressSettings{}, &options).ok());
  EXPECT_EQ(options.pipeline.direct.move, "establishing_dolly");  // "" = the config's
  EXPECT_EQ(options.clip.format, clip::ClipFormat::kMp4);
  EXPECT_EQ(options.pipeline.direct.output.height, 480);

  ASSERT_TRUE(ApplyPressSettings({"dolly_out", "dim_background", "gif", "1080x1920"}, &options).ok());
  EXPECT_EQ(options.pipeline.direct.move, "dolly_out");
  EXPECT_EQ(options.pipeline.direct.effect, "dim_background");
  EXPECT_EQ(options.clip.format, clip::ClipFormat::kGif);
  EXPECT_EQ(options.pipeline.direct.output.width, 1080);
  EXPECT_EQ(options.pipeline.direct.output.height, 1920);

  ASSERT_TRUE(ApplyPressSettings({"", "", "", "source"}, &options).ok());  // the capture's own frame
  EXPECT_EQ(options.pipeline.direct.output.width, 0);
  EXPECT_EQ(options.pipeline.direct.output.height, 0);
  EXPECT_FALSE(ApplyPressSettings({"", "", "mkv", ""}, &options).ok());
}

TEST_F(PressSettingsFileTest, SavedSettingsAreLoadedAgainAndNoFileMeansTheConfigs) {
  const std::filesystem::path path = dir() / "settings.json";
  StatusOr<PressSettings> none = LoadPressSettings(path);
  ASSERT_TRUE(none.ok()) << none.status().ToString();
  EXPECT_TRUE(none->Empty());
  ASSERT_TRUE(SavePressSettings(path, {"dolly_in", "", "webp", "1280x720"}).ok());
  StatusOr<PressSettings> loaded = LoadPressSettings(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->move, "dolly_in");
  EXPECT_EQ(loaded->effect, "");
  EXPECT_EQ(loaded->format, "webp");
  EXPECT_EQ(loaded->size, "1280x720");
}

TEST_F(PressSettingsFileTest, AGarbledFileIsAnErrorNamingIt) {
  const std::filesystem::path path = dir() / "settings.json";
  ASSERT_TRUE(WriteFileAtomically(path, "{\"format\": \"gi").ok());
  StatusOr<PressSettings> garbled = LoadPressSettings(path);
  ASSERT_FALSE(garbled.ok());
  EXPECT_THAT(garbled.status().message(), HasSubstr(path.string()));
  ASSERT_TRUE(WriteFileAtomically(path, R"({"format": "tiff"})").ok());
  StatusOr<PressSettings> wrong = LoadPressSettings(path);
  ASSERT_FALSE(wrong.ok());
  EXPECT_THAT(wrong.status().message(), HasSubstr("format: "));
  EXPECT_THAT(wrong.status().message(), HasSubstr(path.string()));
}

}  // namespace
}  // namespace px::device

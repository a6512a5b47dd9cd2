#include "device/storage/storage_layout.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using StorageLayoutTest = px::testing::TempDirTest;

TEST_F(StorageLayoutTest, PathsFollowTheDocumentedLayout) {
  StorageLayout layout(dir() / "root/");
  EXPECT_EQ(layout.root(), dir() / "root");
  EXPECT_EQ(layout.CaptureDir("000007"), dir() / "root/captures/000007");
  EXPECT_EQ(layout.ClipPath("000007"), dir() / "root/clips/000007.mp4");
  EXPECT_EQ(ClipReportPathFor(layout.ClipPath("000007")), dir() / "root/clips/000007.json");
  EXPECT_EQ(layout.JobRecordPath("000007"), dir() / "root/jobs/000007.json");
}

TEST_F(StorageLayoutTest, RelativeRootBecomesAbsolute) {
  StorageLayout layout("some/where");
  EXPECT_TRUE(layout.root().is_absolute());
  EXPECT_EQ(layout.root(), (fs::current_path() / "some/where").lexically_normal());
}

TEST_F(StorageLayoutTest, PrepareCreatesFoldersAndClearsStaleTemporaries) {
  StorageLayout layout(dir() / "a/b/root");
  ASSERT_TRUE(layout.Prepare().ok());
  EXPECT_TRUE(fs::is_directory(layout.CapturesDir()));
  EXPECT_TRUE(fs::is_directory(layout.ClipsDir()));
  EXPECT_TRUE(fs::is_directory(layout.JobsDir()));
  const fs::path stale = layout.ClipsDir() / ".000001.tmp-99999999-3.mp4";
  ASSERT_TRUE(WriteFileAtomically(stale, "half a clip").ok());
  ASSERT_TRUE(WriteFileAtomically(layout.ClipPath("000002"), "a clip").ok());
  ASSERT_TRUE(layout.Prepare().ok());  // idempotent
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(layout.ClipPath("000002")));
}

// Folders 0750 and files 0640 whatever umask the daemon was started with (by hand, 022 or 000),
// including a store an earlier run left open to everyone.
TEST_F(StorageLayoutTest, TheStoreIsTheDaemonsAloneWhateverTheUmask) {
  for (const mode_t start_umask : {mode_t{0}, mode_t{022}}) {
    ::umask(start_umask);
    const fs::path root = dir() / ("umask" + std::to_string(start_umask));
    fs::create_directories(root / "clips");
    fs::permissions(root, fs::perms::all);  // an old, open store
    StorageLayout layout(root);
    ASSERT_TRUE(layout.Prepare().ok());
    for (const fs::path& folder : {layout.root(), layout.CapturesDir(), layout.ClipsDir(), layout.JobsDir()}) {
      struct stat info {};
      ASSERT_EQ(::stat(folder.c_str(), &info), 0);
      EXPECT_EQ(info.st_mode & 07777, 0750u) << folder << " under umask " << start_umask;
    }
    ASSERT_TRUE(WriteFileAtomically(layout.ClipPath("000001"), "a clip").ok());
    struct stat info {};
    ASSERT_EQ(::stat(layout.ClipPath("000001").c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 0777, 0640u) << "umask " << start_umask;
  }
  ::umask(022);
}

TEST_F(StorageLayoutTest, AStorageGroupOwnsTheFoldersAndIsInherited) {
  StorageLayout layout(dir() / "grouped");
  const gid_t group = ::getegid();  // one the process may always give its files to
  ASSERT_TRUE(layout.Prepare(group).ok());
  struct stat info {};
  ASSERT_EQ(::stat(layout.ClipsDir().c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 07777, 02750u);
  EXPECT_EQ(info.st_gid, group);
}

TEST_F(StorageLayoutTest, PrepareFailsWhenRootIsAFile) {
  ASSERT_TRUE(WriteFileAtomically(dir() / "file", "x").ok());
  Status status = StorageLayout(dir() / "file").Prepare();
  EXPECT_EQ(status.code(), StatusCode::kFailedPrecondition) << status.ToString();
  EXPECT_NE(status.message().find((dir() / "file").string()), std::string::npos) << status.message();
}

TEST(StorageOptionsTest, EmptyRootIsRejectedNamingTheField) {
  StorageOptions options;
  options.root = "";
  EXPECT_EQ(options.Validate().message(), "storage.root: empty");
}

}  // namespace
}  // namespace px::device

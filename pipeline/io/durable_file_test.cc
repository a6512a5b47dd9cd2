#include "pipeline/io/durable_file.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <set>
#include <thread>

#include "tests/testing/temp_dir.h"

namespace px {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using DurableFileTest = px::testing::TempDirTest;

TEST_F(DurableFileTest, WritesAndReplacesContents) {
  const fs::path path = dir() / "a.json";
  ASSERT_TRUE(WriteFileAtomically(path, "first").ok());
  EXPECT_EQ(ReadFileToString(path).value(), "first");
  ASSERT_TRUE(WriteFileAtomically(path, "second, longer").ok());
  EXPECT_EQ(ReadFileToString(path).value(), "second, longer");
  // No temporary is left beside it.
  int entries = 0;
  for (const auto& entry : fs::directory_iterator(dir())) {
    (void)entry;
    ++entries;
  }
  EXPECT_EQ(entries, 1);
}

TEST_F(DurableFileTest, FailedWriteLeavesOldContentAndNoTemporary) {
  const fs::path path = dir() / "target";
  // A non-empty folder in the way makes the final rename fail after the data was written.
  fs::create_directories(path / "occupied");
  Status status = WriteFileAtomically(path, "new bytes");
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(path.string()));
  EXPECT_TRUE(fs::is_directory(path / "occupied"));
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir())) names.insert(entry.path().filename().string());
  EXPECT_EQ(names, std::set<std::string>{"target"});
}

TEST_F(DurableFileTest, MissingFolderIsNotFound) {
  Status status = WriteFileAtomically(dir() / "no_such_folder" / "x", "bytes");
  EXPECT_EQ(status.code(), StatusCode::kNotFound) << status.ToString();
}

// A reader polling the file while a writer alternates two large contents must only ever see one
// of them whole: the rename is the only moment the name changes.
TEST_F(DurableFileTest, ConcurrentReaderNeverSeesPartialContent) {
  const fs::path path = dir() / "big.bin";
  const std::string a(1 << 20, 'a');
  const std::string b((1 << 20) + 4096, 'b');
  ASSERT_TRUE(WriteFileAtomically(path, a).ok());
  std::atomic<bool> done{false};
  std::atomic<int> reads{0};
  std::atomic<int> bad{0};
  std::thread reader([&] {
    while (!done.load()) {
      auto contents = ReadFileToString(path);
      if (!contents.ok() || (*contents != a && *contents != b)) ++bad;
      ++reads;
    }
  });
  for (int i = 0; i < 40; ++i) {
    ASSERT_TRUE(WriteFileAtomically(path, i % 2 ? a : b).ok());
  }
  done = true;
  reader.join();
  EXPECT_EQ(bad.load(), 0) << "of " << reads.load() << " reads";
  EXPECT_GT(reads.load(), 0);
}

// A writer killed at an arbitrary moment (SIGKILL, like a power cut for the page cache's sake)
// leaves the old or the new content, and a stale temporary that RemoveStaleTemporaries clears.
TEST_F(DurableFileTest, KilledWriterLeavesOldOrNewContent) {
  const fs::path path = dir() / "record.json";
  const std::string a(256 * 1024, 'a');
  const std::string b(300 * 1024, 'b');
  ASSERT_TRUE(WriteFileAtomically(path, a).ok());
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(ready[0]);
    for (int i = 0;; ++i) {
      if (!WriteFileAtomically(path, i % 2 ? a : b).ok()) ::_exit(2);
      if (i == 3) (void)!::write(ready[1], "x", 1);  // tell the parent writes are under way
    }
  }
  ::close(ready[1]);
  char byte;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  ::close(ready[0]);
  ::kill(child, SIGKILL);
  int wstatus = 0;
  ::waitpid(child, &wstatus, 0);
  ASSERT_TRUE(WIFSIGNALED(wstatus)) << "the writer failed on its own";
  auto contents = ReadFileToString(path);
  ASSERT_TRUE(contents.ok()) << contents.status().ToString();
  EXPECT_TRUE(*contents == a || *contents == b) << "partial content of " << contents->size() << " bytes";
  RemoveStaleTemporaries(dir());
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir())) names.insert(entry.path().filename().string());
  EXPECT_EQ(names, std::set<std::string>{"record.json"});
}

TEST_F(DurableFileTest, TemporaryNamesKeepExtensionAndAreUnique) {
  const fs::path a = TemporaryPathFor(dir() / "0007.mp4");
  const fs::path b = TemporaryPathFor(dir() / "0007.mp4");
  EXPECT_NE(a, b);
  EXPECT_EQ(a.extension(), ".mp4");
  EXPECT_EQ(a.parent_path(), dir());
  EXPECT_TRUE(IsTemporaryName(a.filename().string()));
  EXPECT_FALSE(IsTemporaryName("0007.mp4"));
}

TEST_F(DurableFileTest, RemovesStaleTemporariesOfDeadProcessesOnly) {
  // A pid that cannot be alive (above the kernel's pid_max of 2^22) marks a crashed writer.
  const fs::path stale = dir() / ".0001.tmp-99999999-0.json";
  const fs::path live = TemporaryPathFor(dir() / "0002.json");  // our own pid, but we are alive...
  const fs::path kept = dir() / "0003.json";
  for (const fs::path& p : {stale, live, kept}) ASSERT_TRUE(WriteFileAtomically(p, "x").ok());
  // ...and our own temporaries count as stale: only the process itself would be writing them.
  EXPECT_EQ(RemoveStaleTemporaries(dir()), 2);
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(live));
  EXPECT_TRUE(fs::exists(kept));
}

TEST_F(DurableFileTest, FreeBytesIsPositiveAndCheckNamesFolderAndSizes) {
  auto free_bytes = FreeBytes(dir());
  ASSERT_TRUE(free_bytes.ok()) << free_bytes.status().ToString();
  EXPECT_GT(*free_bytes, 0u);
  EXPECT_TRUE(CheckFreeSpace(dir(), 1).ok());
  // Ask for more than exists: the error says how much is free and how much was needed.
  const uint64_t need = *free_bytes + 500ull * 1000 * 1000 * 1000;
  Status status = CheckFreeSpace(dir(), need);
  EXPECT_EQ(status.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(status.message(), MatchesRegex("disk full: [0-9]+ MB free under " + dir().string() + ", need [0-9]+ MB"));
}

TEST(DiskFullErrorTest, MessageRoundsFreeDownAndNeedUp) {
  Status status = DiskFullError("/var/lib/parallax", 12'900'000, 79'000'001);
  EXPECT_EQ(status.code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(status.message(), "disk full: 12 MB free under /var/lib/parallax, need 80 MB");
}

TEST(ErrnoToStatusTest, NoSpaceIsDiskFullNamingThePath) {
  Status status = ErrnoToStatus(ENOSPC, "write", "/tmp/x.mp4", 80'000'000);
  EXPECT_EQ(status.code(), StatusCode::kResourceExhausted);
  EXPECT_THAT(status.message(), MatchesRegex("write /tmp/x.mp4: disk full: [0-9]+ MB free under /tmp, need 80 MB"));
  EXPECT_EQ(ErrnoToStatus(EACCES, "create", "/x").code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(ErrnoToStatus(EIO, "read", "/x").code(), StatusCode::kDataLoss);
}

// A real ENOSPC: /dev/full fails every write with it. Exercised through the same errno mapping
// WriteFileAtomically uses.
TEST(ErrnoToStatusTest, DevFullWriteReportsDiskFull) {
  int fd = ::open("/dev/full", O_WRONLY | O_CLOEXEC);
  if (fd < 0) GTEST_SKIP() << "/dev/full is not available";
  const char byte = 0;
  ssize_t n = ::write(fd, &byte, 1);
  int err = errno;
  ::close(fd);
  ASSERT_LT(n, 0);
  Status status = ErrnoToStatus(err, "write", "/dev/full", 1);
  EXPECT_EQ(status.code(), StatusCode::kResourceExhausted) << status.ToString();
  EXPECT_THAT(status.message(), HasSubstr("disk full"));
}

}  // namespace
}  // namespace px

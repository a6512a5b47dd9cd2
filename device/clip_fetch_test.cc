// A clip fetch never leaves the clip store: each trick a client or a tampered store could play
// (path-like ids, a journal record naming another file, a symbolic link as the clip or as the
// clips folder, a hard link, a FIFO or a folder under the clip's name) is refused with the reason, and the
// file outside the store is never read.
#include "device/clip_fetch.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class ClipFetchTest : public px::testing::TempDirTest {
 protected:
  void SetUp() override {
    layout_ = std::make_unique<StorageLayout>(dir() / "store");
    ASSERT_TRUE(layout_->Prepare().ok());
    secret_ = dir() / "secret.txt";
    ASSERT_TRUE(WriteFileAtomically(secret_, "the secret outside the store").ok());
  }
  JobRecord Done(const std::string& id) const {
    JobRecord record;
    record.id = id;
    record.state = JobState::kDone;
    record.clip_path = layout_->ClipPath(id).string();
    return record;
  }
  StatusOr<nlohmann::json> Fetch(const std::string& id, const JobRecord& record, bool inline_bytes = true) const {
    return FetchClipReply(id, record, inline_bytes, *layout_);
  }
  void ExpectRefusedWithoutTheSecret(const StatusOr<nlohmann::json>& reply, StatusCode code, const std::string& why) {
    ASSERT_FALSE(reply.ok()) << reply->dump();
    EXPECT_EQ(reply.status().code(), code) << reply.status().ToString();
    EXPECT_THAT(reply.status().message(), HasSubstr(why));
    EXPECT_THAT(reply.status().message(), ::testing::Not(HasSubstr("the secret")));
  }

  std::unique_ptr<StorageLayout> layout_;
  fs::path secret_;
};

TEST_F(ClipFetchTest, AGoodClipIsServedFromTheStore) {
  ASSERT_TRUE(WriteFileAtomically(layout_->ClipPath("000001"), "clip bytes").ok());
  auto reply = Fetch("000001", Done("000001"));
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ((*reply)["path"], layout_->ClipPath("000001").string());
  EXPECT_EQ((*reply)["bytes"], 10);
  EXPECT_EQ((*reply)["data"], Base64Encode("clip bytes"));
}

TEST_F(ClipFetchTest, IdsThatAreNotJobIdsAreRefused) {
  for (const std::string& id : {std::string("../secret"), secret_.string(), std::string("000001/../../x")}) {
    JobRecord record = Done("000001");
    ExpectRefusedWithoutTheSecret(Fetch(id, record), StatusCode::kInvalidArgument, "not a job id");
  }
}

TEST_F(ClipFetchTest, AJournalRecordNamingAnotherFileIsIgnored) {
  // A tampered (or moved) journal names the secret: the store's own clip is what counts.
  JobRecord record = Done("000002");
  record.clip_path = secret_.string();
  ExpectRefusedWithoutTheSecret(Fetch("000002", record), StatusCode::kDataLoss, "store/clips/000002.mp4 is missing");
  record.clip_path = (layout_->ClipsDir() / ".." / ".." / "secret.txt").string();
  ASSERT_TRUE(WriteFileAtomically(layout_->ClipPath("000002"), "real clip").ok());
  auto reply = Fetch("000002", record);
  ASSERT_TRUE(reply.ok()) << reply.status().ToString();
  EXPECT_EQ((*reply)["data"], Base64Encode("real clip"));
}

TEST_F(ClipFetchTest, ASymbolicLinkAsTheClipIsNotFollowed) {
  fs::create_symlink(secret_, layout_->ClipPath("000003"));
  ExpectRefusedWithoutTheSecret(Fetch("000003", Done("000003")),
                                StatusCode::kPermissionDenied,
                                "is a symbolic link; refusing to follow it out of the clip store");
  // A relative link climbing out is the same.
  fs::create_symlink("../../secret.txt", layout_->ClipPath("000004"));
  ExpectRefusedWithoutTheSecret(Fetch("000004", Done("000004")), StatusCode::kPermissionDenied, "symbolic link");
}

TEST_F(ClipFetchTest, ASymbolicLinkAsTheClipsFolderIsNotFollowed) {
  const fs::path elsewhere = dir() / "elsewhere";
  fs::create_directories(elsewhere);
  ASSERT_TRUE(WriteFileAtomically(elsewhere / "000005.mp4", "the secret clip").ok());
  fs::remove_all(layout_->ClipsDir());
  fs::create_directory_symlink(elsewhere, layout_->ClipsDir());
  ExpectRefusedWithoutTheSecret(Fetch("000005", Done("000005")),
                                StatusCode::kPermissionDenied,
                                "is not a folder of the store (a symbolic link?)");
}

TEST_F(ClipFetchTest, AFifoOrAFolderUnderTheClipsNameIsRefusedWithoutHanging) {
  ASSERT_EQ(::mkfifo(layout_->ClipPath("000006").c_str(), 0600), 0);
  ExpectRefusedWithoutTheSecret(Fetch("000006", Done("000006")), StatusCode::kPermissionDenied, "not a regular file");
  fs::create_directory(layout_->ClipPath("000007"));
  ExpectRefusedWithoutTheSecret(Fetch("000007", Done("000007")), StatusCode::kPermissionDenied, "not a regular file");
}

TEST_F(ClipFetchTest, AHardLinkPlantedAsTheClipIsRefused) {
  // A hard link shares the secret's inode: no path trick to see, only its link count shows it.
  fs::create_hard_link(secret_, layout_->ClipPath("000008"));
  ExpectRefusedWithoutTheSecret(
      Fetch("000008", Done("000008")), StatusCode::kPermissionDenied, "has 2 hard links; refusing to read it");
}

TEST_F(ClipFetchTest, JobsWithoutAClipSayWhy) {
  JobRecord failed = Done("000008");
  failed.state = JobState::kFailed;
  failed.error = "DATA_LOSS: frame 0: corrupt";
  EXPECT_THAT(Fetch("000008", failed).status().message(), HasSubstr("failed, it has no clip: DATA_LOSS"));
  JobRecord saved = Done("000009");
  saved.state = JobState::kSaved;
  EXPECT_THAT(Fetch("000009", saved).status().message(), HasSubstr("is saved; its clip is not made yet"));
  EXPECT_EQ(FetchClipReply("000010", std::nullopt, false, *layout_).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace px::device

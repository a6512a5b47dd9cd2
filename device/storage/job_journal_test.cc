#include "device/storage/job_journal.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "pipeline/io/durable_file.h"
#include "tests/testing/temp_dir.h"

namespace px::device {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using JobJournalTest = px::testing::TempDirTest;

JobRecord MakeRecord(const std::string& id, JobState state) {
  JobRecord record;
  record.id = id;
  record.state = state;
  record.created_at = NowIso8601Utc();
  record.updated_at = record.created_at;
  record.capture_ms = 12.5;
  record.attempts = 1;
  record.error = state == JobState::kFailed ? "UNAVAILABLE: camera gone" : "";
  return record;
}

TEST_F(JobJournalTest, RecordsSurviveReopening) {
  {
    auto journal = JobJournal::Open(dir()).value();
    const std::string a = journal->NewId();
    const std::string b = journal->NewId();
    EXPECT_EQ(a, "000001");
    EXPECT_EQ(b, "000002");
    ASSERT_TRUE(journal->Put(MakeRecord(a, JobState::kDone)).ok());
    ASSERT_TRUE(journal->Put(MakeRecord(b, JobState::kSaved)).ok());
    JobRecord failed = MakeRecord(b, JobState::kFailed);
    ASSERT_TRUE(journal->Put(failed).ok());  // a state change rewrites the record
  }
  auto journal = JobJournal::Open(dir()).value();
  std::vector<JobRecord> records = journal->List();
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0].id, "000001");
  EXPECT_EQ(records[0].state, JobState::kDone);
  EXPECT_EQ(records[1].state, JobState::kFailed);
  EXPECT_EQ(records[1].error, "UNAVAILABLE: camera gone");
  EXPECT_DOUBLE_EQ(records[1].capture_ms, 12.5);
  // New ids continue after the highest one on disk, and after names taken elsewhere.
  EXPECT_EQ(journal->NewId(), "000003");
  EXPECT_EQ(journal->NewId({"000010", "not-an-id"}), "000011");
}

TEST_F(JobJournalTest, CorruptRecordIsMovedAsideNotFatal) {
  ASSERT_TRUE(WriteFileAtomically(dir() / "000004.json", "{\"id\": \"000004\", \"state\": \"exploded\"}").ok());
  ASSERT_TRUE(WriteFileAtomically(dir() / "000005.json", "{ truncated").ok());
  auto journal = JobJournal::Open(dir());
  ASSERT_TRUE(journal.ok()) << journal.status().ToString();
  EXPECT_TRUE((*journal)->List().empty());
  EXPECT_TRUE(fs::exists(dir() / "000004.json.corrupt"));
  EXPECT_TRUE(fs::exists(dir() / "000005.json.corrupt"));
}

TEST(JobRecordJsonTest, RoundTripsAndNamesBadFields) {
  JobRecord record = MakeRecord("000042", JobState::kProcessing);
  record.note = "90 frames";
  auto parsed = JobRecordFromJson(JobRecordToJson(record), "r");
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  EXPECT_EQ(JobRecordToJson(*parsed), JobRecordToJson(record));

  nlohmann::json bad = JobRecordToJson(record);
  bad["state"] = "exploded";
  EXPECT_THAT(JobRecordFromJson(bad, "r").status().message(), HasSubstr("r.state: 'exploded' is not one of"));
  bad = JobRecordToJson(record);
  bad["attempts"] = "two";
  EXPECT_EQ(JobRecordFromJson(bad, "r").status().message(), "r.attempts: want an integer, got string");
  bad = JobRecordToJson(record);
  bad["id"] = "../etc";
  EXPECT_THAT(JobRecordFromJson(bad, "r").status().message(), HasSubstr("r.id: '../etc' is not a job id"));
}

TEST(JobStateTest, NamesRoundTrip) {
  for (JobState state :
       {JobState::kCapturing, JobState::kSaved, JobState::kProcessing, JobState::kDone, JobState::kFailed}) {
    EXPECT_EQ(ParseJobState(JobStateName(state)).value(), state);
  }
  EXPECT_TRUE(IsFinal(JobState::kDone));
  EXPECT_FALSE(IsFinal(JobState::kSaved));
}

}  // namespace
}  // namespace px::device

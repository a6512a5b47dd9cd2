// A fresh temporary folder per test, removed afterwards (kept when PX_KEEP_TEST_DIRS is set).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>

namespace px::testing {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A fixture whose dir() is a fresh TempDir for every test.
class TempDirTest : public ::testing::Test {
 protected:
  const std::filesystem::path& dir() const { return temp_.path(); }

 private:
  TempDir temp_;
};

}  // namespace px::testing

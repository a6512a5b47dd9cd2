#include "tests/testing/temp_dir.h"

#include <cstdlib>
#include <string>

#include "pipeline/core/check.h"

namespace px::testing {

TempDir::TempDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "px_test_XXXXXX").string();
  PX_CHECK(mkdtemp(pattern.data()) != nullptr) << "mkdtemp failed for " << pattern;
  path_ = pattern;
}

TempDir::~TempDir() {
  if (std::getenv("PX_KEEP_TEST_DIRS") != nullptr) return;
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

}  // namespace px::testing

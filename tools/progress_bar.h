// A one-line progress display on stderr for long steps ("depth  [#####     ]  52%").
#pragma once

#include <string>

namespace px::cli {

class ProgressBar {
 public:
  // Quiet bars print nothing (for --json output or non-interactive runs that want clean logs).
  explicit ProgressBar(bool quiet = false) : quiet_(quiet) {}
  ~ProgressBar();
  void Update(const std::string& stage, double fraction);
  void Finish();

 private:
  bool quiet_;
  std::string stage_;
  int last_percent_ = -1;
  bool open_line_ = false;
};

}  // namespace px::cli

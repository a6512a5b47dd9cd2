#include "tools/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace px::cli {

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Update(const std::string& stage, double fraction) {
  if (quiet_) return;
  const int percent = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0);
  if (stage == stage_ && percent == last_percent_) return;
  const bool interactive = isatty(STDERR_FILENO) != 0;
  // On a pipe or log file, print one line per stage at its start and end only.
  if (!interactive && stage == stage_ && percent != 100) return;
  if (stage != stage_ && open_line_) std::fputc('\n', stderr);
  stage_ = stage;
  last_percent_ = percent;
  constexpr int kWidth = 30;
  const int filled = percent * kWidth / 100;
  std::fprintf(stderr,
               "%s%-8s [%s%s] %3d%%",
               interactive ? "\r" : "",
               stage.c_str(),
               std::string(filled, '#').c_str(),
               std::string(kWidth - filled, ' ').c_str(),
               percent);
  if (interactive) {
    open_line_ = true;
  } else {
    std::fputc('\n', stderr);
  }
  std::fflush(stderr);
}

void ProgressBar::Finish() {
  if (open_line_) std::fputc('\n', stderr);
  open_line_ = false;
}

}  // namespace px::cli

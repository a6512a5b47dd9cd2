#include "pipeline/direct/direct_options.h"

#include <array>
#include <cmath>
#include <sstream>

namespace px {

namespace {
constexpr std::array<const char*, 2> kMoves = {"auto", "establishing_dolly"};
}  // namespace

bool IsKnownMove(const std::string& move) {
  for (const char* known : kMoves) {
    if (move == known) return true;
  }
  return false;
}

Status DirectOptions::Validate() const {
  std::ostringstream error;
  if (!IsKnownMove(move)) {
    error << "direct.move: unknown move \"" << move << "\", want one of";
    for (const char* known : kMoves) error << " " << known;
  } else if (!(duration_s > 0 && duration_s <= 60)) {
    error << "direct.duration_s: " << duration_s << " is outside (0, 60]";
  } else if (!(fps > 0 && fps <= 240)) {
    error << "direct.fps: " << fps << " is outside (0, 240]";
  }
  if (error.str().empty()) return OkStatus();
  return InvalidArgumentError(error.str());
}

}  // namespace px

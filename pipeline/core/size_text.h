// "640x480": an image's size as messages and logs write it.
#pragma once

#include <cstdint>
#include <string>

namespace px {

inline std::string SizeText(int64_t width, int64_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace px

// The error every options struct's Validate() returns for a value outside its range.
#pragma once

#include <sstream>
#include <string_view>

#include "pipeline/core/status.h"

namespace px {

// INVALID_ARGUMENT "<options>: <field> = <value> is outside <range>", e.g. "depth options:
// matching.num_planes = 1 is outside 0 or [2, 1024]".
template <typename T>
Status OptionOutOfRange(std::string_view options, std::string_view field, const T& value, std::string_view range) {
  std::ostringstream text;
  text << options << ": " << field << " = " << value << " is outside " << range;
  return InvalidArgumentError(text.str());
}

}  // namespace px

// Names of Linux input key codes (linux/input-event-codes.h) for the trigger config:
// "KEY_CAMERA", "KEY_ENTER", "BTN_0", or a number ("212").
#pragma once

#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px::device {

// The code for a name from the table or a decimal number in [0, KEY_MAX]. INVALID_ARGUMENT
// otherwise, listing a few known names.
StatusOr<int> ParseKeyCode(std::string_view text);
// "KEY_CAMERA" for a known code, else the number.
std::string KeyCodeName(int code);

}  // namespace px::device

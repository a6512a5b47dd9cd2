#include "device/trigger/key_codes.h"

#include <linux/input-event-codes.h>

#include <charconv>
#include <utility>
#include <vector>

namespace px::device {
namespace {

#define PX_KEY(name) \
  { #name, name }
// The keys a one-button camera, a remote or a keyboard used for testing is likely to send.
const std::vector<std::pair<std::string_view, int>>& KeyTable() {
  static const std::vector<std::pair<std::string_view, int>> kKeys = {
      PX_KEY(KEY_CAMERA),
      PX_KEY(KEY_CAMERA_FOCUS),
      PX_KEY(KEY_RECORD),
      PX_KEY(KEY_ENTER),
      PX_KEY(KEY_KPENTER),
      PX_KEY(KEY_SPACE),
      PX_KEY(KEY_OK),
      PX_KEY(KEY_SELECT),
      PX_KEY(KEY_PLAY),
      PX_KEY(KEY_PLAYPAUSE),
      PX_KEY(KEY_PAUSE),
      PX_KEY(KEY_STOP),
      PX_KEY(KEY_MEDIA),
      PX_KEY(KEY_VOLUMEUP),
      PX_KEY(KEY_VOLUMEDOWN),
      PX_KEY(KEY_POWER),
      PX_KEY(KEY_HOME),
      PX_KEY(KEY_MENU),
      PX_KEY(KEY_ESC),
      PX_KEY(KEY_PROG1),
      PX_KEY(KEY_PROG2),
      PX_KEY(KEY_PROG3),
      PX_KEY(KEY_PROG4),
      PX_KEY(KEY_UP),
      PX_KEY(KEY_DOWN),
      PX_KEY(KEY_LEFT),
      PX_KEY(KEY_RIGHT),
      PX_KEY(KEY_1),
      PX_KEY(KEY_2),
      PX_KEY(KEY_3),
      PX_KEY(KEY_4),
      PX_KEY(KEY_5),
      PX_KEY(KEY_6),
      PX_KEY(KEY_7),
      PX_KEY(KEY_8),
      PX_KEY(KEY_9),
      PX_KEY(KEY_0),
      PX_KEY(KEY_A),
      PX_KEY(KEY_B),
      PX_KEY(KEY_C),
      PX_KEY(KEY_P),
      PX_KEY(KEY_Q),
      PX_KEY(KEY_S),
      PX_KEY(KEY_F1),
      PX_KEY(KEY_F2),
      PX_KEY(KEY_F3),
      PX_KEY(KEY_F4),
      PX_KEY(KEY_F5),
      PX_KEY(KEY_F6),
      PX_KEY(KEY_F7),
      PX_KEY(KEY_F8),
      PX_KEY(KEY_F9),
      PX_KEY(KEY_F10),
      PX_KEY(KEY_F11),
      PX_KEY(KEY_F12),
      PX_KEY(BTN_0),
      PX_KEY(BTN_1),
      PX_KEY(BTN_2),
      PX_KEY(BTN_3),
      PX_KEY(BTN_4),
      PX_KEY(BTN_5),
      PX_KEY(BTN_6),
      PX_KEY(BTN_7),
      PX_KEY(BTN_8),
      PX_KEY(BTN_9),
      PX_KEY(BTN_LEFT),
      PX_KEY(BTN_RIGHT),
      PX_KEY(BTN_MIDDLE),
      PX_KEY(BTN_TRIGGER),
      PX_KEY(BTN_SOUTH),
      PX_KEY(BTN_EAST),
      PX_KEY(BTN_NORTH),
      PX_KEY(BTN_WEST),
      PX_KEY(BTN_START),
      PX_KEY(BTN_SELECT),
      PX_KEY(BTN_MODE),
      PX_KEY(BTN_TL),
      PX_KEY(BTN_TR),
      PX_KEY(BTN_TRIGGER_HAPPY1),
  };
  return kKeys;
}
#undef PX_KEY

}  // namespace

StatusOr<int> ParseKeyCode(std::string_view text) {
  for (const auto& [name, code] : KeyTable()) {
    if (name == text) return code;
  }
  int code = -1;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), code);
  if (!text.empty() && error == std::errc() && end == text.data() + text.size()) {
    if (code >= 0 && code <= KEY_MAX) return code;
    return InvalidArgumentError("key code " + std::string(text) + " is not in [0, " + std::to_string(KEY_MAX) + "]");
  }
  return InvalidArgumentError("'" + std::string(text) +
                              "' is not a known key name (e.g. KEY_CAMERA, KEY_ENTER, KEY_SPACE, BTN_0) or a number "
                              "from linux/input-event-codes.h");
}

std::string KeyCodeName(int code) {
  for (const auto& [name, value] : KeyTable()) {
    if (value == code) return std::string(name);
  }
  return std::to_string(code);
}

}  // namespace px::device

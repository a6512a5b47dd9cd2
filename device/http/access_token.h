// The web app's access token: 32 random bytes written as 64 hex digits in the daemon's state
// (<storage root>/http_token, mode 0600), made on first start and kept across restarts, so a
// phone logged in once stays logged in. parallaxd --print-token shows it.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px::device {

// Reads the token at `path`, or makes one there (atomically, mode 0600 from its creation) when
// there is none. A file
// that holds anything but 64 hex digits is an error naming it (never silently replaced: a user
// may have written their own on purpose, and a half-written one cannot happen).
StatusOr<std::string> LoadOrCreateAccessToken(const std::filesystem::path& path);

// Compares in time independent of where the strings first differ.
bool TokensEqual(std::string_view a, std::string_view b);

}  // namespace px::device

// SHA-256 (FIPS 180-4) of a byte buffer, as lowercase hex: the checksum recordings keep for
// each frame file, so a damaged file is caught before it is decoded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace px::capture {

// 64 lowercase hex digits.
std::string Sha256Hex(std::span<const uint8_t> bytes);
// The same of a text's bytes (a file read into a string, a fingerprint).
std::string Sha256HexOfText(std::string_view text);

}  // namespace px::capture

// Little-endian reading and writing of PTP's primitive types: integers, strings (a count byte,
// then UCS-2 characters ending in a NUL) and arrays (a 32-bit count, then elements). The reader
// checks every access against the end of the buffer and names the field in its error.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/status.h"

namespace px::ptp {

class ByteWriter {
 public:
  void U8(uint8_t value) { bytes_.push_back(value); }
  void U16(uint16_t value);
  void U32(uint32_t value);
  void U64(uint64_t value);
  // ASCII/Latin-1 text as UCS-2; at most 254 characters (the count byte includes the NUL).
  void String(std::string_view text);
  void U16Array(const std::vector<uint16_t>& values);
  void U32Array(const std::vector<uint32_t>& values);
  void Bytes(std::span<const uint8_t> bytes) { bytes_.insert(bytes_.end(), bytes.begin(), bytes.end()); }
  // Overwrites 4 bytes at `offset` (a length written after the fact).
  void PatchU32(size_t offset, uint32_t value);

  size_t size() const { return bytes_.size(); }
  const std::vector<uint8_t>& bytes() const& { return bytes_; }
  std::vector<uint8_t> Take() && { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

class ByteReader {
 public:
  // `what` names the structure in errors: "DeviceInfo: field Model at byte 57: ...".
  ByteReader(std::span<const uint8_t> bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

  StatusOr<uint8_t> U8(std::string_view field);
  StatusOr<uint16_t> U16(std::string_view field);
  StatusOr<uint32_t> U32(std::string_view field);
  StatusOr<uint64_t> U64(std::string_view field);
  // Non-ASCII UCS-2 characters become '?'. A string without its NUL is an error.
  StatusOr<std::string> String(std::string_view field);
  StatusOr<std::vector<uint16_t>> U16Array(std::string_view field);
  StatusOr<std::vector<uint32_t>> U32Array(std::string_view field);

  size_t offset() const { return offset_; }
  size_t remaining() const { return bytes_.size() - offset_; }

 private:
  Status Need(size_t count, std::string_view field, std::string_view detail = {}) const;

  std::span<const uint8_t> bytes_;
  std::string what_;
  size_t offset_ = 0;
};

uint16_t LoadU16(const uint8_t* p);
uint32_t LoadU32(const uint8_t* p);

}  // namespace px::ptp

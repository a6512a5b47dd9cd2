#include "drivers/ptp/ptp_bytes.h"

#include <algorithm>

namespace px::ptp {

uint16_t LoadU16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
uint32_t LoadU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | (static_cast<uint32_t>(p[1]) << 8) | (static_cast<uint32_t>(p[2]) << 16) |
         (static_cast<uint32_t>(p[3]) << 24);
}

void ByteWriter::U16(uint16_t value) {
  U8(static_cast<uint8_t>(value));
  U8(static_cast<uint8_t>(value >> 8));
}

void ByteWriter::U32(uint32_t value) {
  U16(static_cast<uint16_t>(value));
  U16(static_cast<uint16_t>(value >> 16));
}

void ByteWriter::U64(uint64_t value) {
  U32(static_cast<uint32_t>(value));
  U32(static_cast<uint32_t>(value >> 32));
}

void ByteWriter::String(std::string_view text) {
  if (text.empty()) {
    U8(0);
    return;
  }
  const size_t chars = std::min<size_t>(text.size(), 254);
  U8(static_cast<uint8_t>(chars + 1));
  for (size_t i = 0; i < chars; ++i) U16(static_cast<uint8_t>(text[i]));
  U16(0);
}

void ByteWriter::U16Array(const std::vector<uint16_t>& values) {
  U32(static_cast<uint32_t>(values.size()));
  for (uint16_t v : values) U16(v);
}

void ByteWriter::U32Array(const std::vector<uint32_t>& values) {
  U32(static_cast<uint32_t>(values.size()));
  for (uint32_t v : values) U32(v);
}

void ByteWriter::PatchU32(size_t offset, uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes_.at(offset + i) = static_cast<uint8_t>(value >> (8 * i));
}

Status ByteReader::Need(size_t count, std::string_view field, std::string_view detail) const {
  if (count <= remaining()) return OkStatus();
  return DataLossError(what_ + ": field " + std::string(field) + " at byte " + std::to_string(offset_) + ": needs " +
                       std::to_string(count) + " bytes" + (detail.empty() ? "" : " (" + std::string(detail) + ")") +
                       ", only " + std::to_string(remaining()) + " left of " + std::to_string(bytes_.size()));
}

StatusOr<uint8_t> ByteReader::U8(std::string_view field) {
  PX_RETURN_IF_ERROR(Need(1, field));
  return bytes_[offset_++];
}

StatusOr<uint16_t> ByteReader::U16(std::string_view field) {
  PX_RETURN_IF_ERROR(Need(2, field));
  const uint16_t value = LoadU16(bytes_.data() + offset_);
  offset_ += 2;
  return value;
}

StatusOr<uint32_t> ByteReader::U32(std::string_view field) {
  PX_RETURN_IF_ERROR(Need(4, field));
  const uint32_t value = LoadU32(bytes_.data() + offset_);
  offset_ += 4;
  return value;
}

StatusOr<uint64_t> ByteReader::U64(std::string_view field) {
  PX_ASSIGN_OR_RETURN(uint32_t low, U32(field));
  PX_ASSIGN_OR_RETURN(uint32_t high, U32(field));
  return (static_cast<uint64_t>(high) << 32) | low;
}

StatusOr<std::string> ByteReader::String(std::string_view field) {
  const size_t start = offset_;
  PX_ASSIGN_OR_RETURN(uint8_t count, U8(field));
  if (count == 0) return std::string();
  PX_RETURN_IF_ERROR(Need(size_t{count} * 2, field, std::to_string(count) + " UCS-2 characters"));
  std::string text;
  text.reserve(count);
  for (int i = 0; i < count; ++i) {
    const uint16_t c = LoadU16(bytes_.data() + offset_ + 2 * i);
    if (i + 1 == count) {
      if (c != 0) {
        return DataLossError(what_ + ": field " + std::string(field) + " at byte " + std::to_string(start) +
                             ": string of " + std::to_string(count) + " characters does not end in NUL");
      }
    } else {
      text.push_back(c < 0x80 && c != 0 ? static_cast<char>(c) : '?');
    }
  }
  offset_ += size_t{count} * 2;
  return text;
}

StatusOr<std::vector<uint16_t>> ByteReader::U16Array(std::string_view field) {
  PX_ASSIGN_OR_RETURN(uint32_t count, U32(field));
  // Checked before allocating, so a garbled count cannot ask for gigabytes.
  PX_RETURN_IF_ERROR(Need(size_t{count} * 2, field, "array of " + std::to_string(count) + " x UINT16"));
  std::vector<uint16_t> values(count);
  for (uint32_t i = 0; i < count; ++i) values[i] = LoadU16(bytes_.data() + offset_ + 2 * i);
  offset_ += size_t{count} * 2;
  return values;
}

StatusOr<std::vector<uint32_t>> ByteReader::U32Array(std::string_view field) {
  PX_ASSIGN_OR_RETURN(uint32_t count, U32(field));
  PX_RETURN_IF_ERROR(Need(size_t{count} * 4, field, "array of " + std::to_string(count) + " x UINT32"));
  std::vector<uint32_t> values(count);
  for (uint32_t i = 0; i < count; ++i) values[i] = LoadU32(bytes_.data() + offset_ + 4 * i);
  offset_ += size_t{count} * 4;
  return values;
}

}  // namespace px::ptp

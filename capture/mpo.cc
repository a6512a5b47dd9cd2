#include "capture/mpo.h"

#include <cstring>

namespace px {
namespace {

constexpr uint16_t kMpEntryTag = 0xB002;
constexpr size_t kMpEntryBytes = 16;
constexpr size_t kMaxImages = 64;

// Reads the TIFF structure's integers in its byte order; false past the end.
class TiffReader {
 public:
  TiffReader(const uint8_t* data, size_t size, bool big_endian) : data_(data), size_(size), big_(big_endian) {}
  bool U16(size_t at, uint16_t* value) const {
    if (at + 2 > size_) return false;
    *value = big_ ? static_cast<uint16_t>(data_[at] << 8 | data_[at + 1])
                  : static_cast<uint16_t>(data_[at + 1] << 8 | data_[at]);
    return true;
  }
  bool U32(size_t at, uint32_t* value) const {
    if (at + 4 > size_) return false;
    const uint8_t* p = data_ + at;
    *value = big_ ? (uint32_t{p[0]} << 24 | uint32_t{p[1]} << 16 | uint32_t{p[2]} << 8 | p[3])
                  : (uint32_t{p[3]} << 24 | uint32_t{p[2]} << 16 | uint32_t{p[1]} << 8 | p[0]);
    return true;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  bool big_;
};

// The offset of the MPF TIFF header (after "MPF\0" in the first APP2 that has it) and its length,
// walking the first image's marker segments up to its scan.
bool FindMpfHeader(const std::vector<uint8_t>& bytes, size_t* start, size_t* length) {
  size_t at = 2;
  while (at + 4 <= bytes.size() && bytes[at] == 0xFF) {
    const uint8_t marker = bytes[at + 1];
    if (marker == 0xDA || marker == 0xD9) return false;  // start of scan or end of image: no index
    const size_t segment = static_cast<size_t>(bytes[at + 2]) << 8 | bytes[at + 3];
    if (segment < 2 || at + 2 + segment > bytes.size()) return false;
    if (marker == 0xE2 && segment >= 2 + 4 + 8 && std::memcmp(&bytes[at + 4], "MPF\0", 4) == 0) {
      *start = at + 8;
      *length = segment - 6;
      return true;
    }
    at += 2 + segment;
  }
  return false;
}

}  // namespace

StatusOr<std::vector<std::vector<uint8_t>>> SplitMpo(const std::vector<uint8_t>& bytes, const std::string& name) {
  if (bytes.size() < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8) {
    return DataLossError(name + ": not a JPEG (an MPO file starts with one)");
  }
  size_t header = 0, header_length = 0;
  if (!FindMpfHeader(bytes, &header, &header_length)) {
    return DataLossError(name + ": no MP index (no APP2 'MPF' segment before the first image's scan)");
  }
  const uint8_t* tiff = bytes.data() + header;
  bool big_endian;
  if (std::memcmp(tiff, "MM\0*", 4) == 0) {
    big_endian = true;
  } else if (std::memcmp(tiff, "II*\0", 4) == 0) {
    big_endian = false;
  } else {
    return DataLossError(name + ": the MP index has no TIFF byte order mark");
  }
  const TiffReader reader(tiff, header_length, big_endian);
  uint32_t ifd = 0;
  uint16_t entries = 0;
  if (!reader.U32(4, &ifd) || !reader.U16(ifd, &entries)) return DataLossError(name + ": the MP index is truncated");
  uint32_t mp_entry_count = 0, mp_entry_offset = 0;
  for (uint16_t i = 0; i < entries; ++i) {
    const size_t entry = ifd + 2 + 12 * static_cast<size_t>(i);
    uint16_t tag = 0;
    if (!reader.U16(entry, &tag)) return DataLossError(name + ": the MP index is truncated");
    if (tag != kMpEntryTag) continue;
    if (!reader.U32(entry + 4, &mp_entry_count) || !reader.U32(entry + 8, &mp_entry_offset)) {
      return DataLossError(name + ": the MP index is truncated");
    }
  }
  if (mp_entry_count == 0 || mp_entry_count % kMpEntryBytes != 0 || mp_entry_count / kMpEntryBytes > kMaxImages) {
    return DataLossError(name + ": the MP index lists no images (MP entry tag missing or of a bad size)");
  }
  std::vector<std::vector<uint8_t>> images;
  for (size_t i = 0; i < mp_entry_count / kMpEntryBytes; ++i) {
    uint32_t size = 0, offset = 0;
    const size_t entry = mp_entry_offset + kMpEntryBytes * i;
    if (!reader.U32(entry + 4, &size) || !reader.U32(entry + 8, &offset)) {
      return DataLossError(name + ": the MP index's entry " + std::to_string(i) + " is truncated");
    }
    // The first image starts the file; the others' offsets count from the MP index's TIFF header.
    const size_t begin = i == 0 ? 0 : header + offset;
    if (size < 4 || begin >= bytes.size() || size > bytes.size() - begin) {
      return DataLossError(name + ": image " + std::to_string(i) + " of the MP index (" + std::to_string(size) +
                           " bytes at " + std::to_string(begin) + ") lies outside the file's " +
                           std::to_string(bytes.size()) + " bytes");
    }
    if (bytes[begin] != 0xFF || bytes[begin + 1] != 0xD8) {
      return DataLossError(name + ": image " + std::to_string(i) + " of the MP index is not a JPEG");
    }
    images.emplace_back(bytes.begin() + static_cast<long>(begin), bytes.begin() + static_cast<long>(begin + size));
  }
  return images;
}

}  // namespace px

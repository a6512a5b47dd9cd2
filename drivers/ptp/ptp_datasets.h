// The two PTP datasets the initiator reads: DeviceInfo (what the camera can do) and ObjectInfo
// (what a captured object is). Field order and types follow ISO 15740 sections 5.5.1 and 5.5.2.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::ptp {

struct DeviceInfo {
  uint16_t standard_version = 100;  // 1.00
  uint32_t vendor_extension_id = 0;
  uint16_t vendor_extension_version = 0;
  std::string vendor_extension_desc;
  uint16_t functional_mode = 0;
  std::vector<uint16_t> operations_supported;
  std::vector<uint16_t> events_supported;
  std::vector<uint16_t> device_properties_supported;
  std::vector<uint16_t> capture_formats;
  std::vector<uint16_t> image_formats;
  std::string manufacturer;
  std::string model;
  std::string device_version;
  std::string serial_number;

  bool SupportsOperation(uint16_t code) const;
  bool SupportsProperty(uint16_t code) const;
  friend bool operator==(const DeviceInfo&, const DeviceInfo&) = default;
};

struct ObjectInfo {
  uint32_t storage_id = 0;
  uint16_t object_format = 0;
  uint16_t protection_status = 0;
  uint32_t object_compressed_size = 0;
  uint16_t thumb_format = 0;
  uint32_t thumb_compressed_size = 0;
  uint32_t thumb_pix_width = 0;
  uint32_t thumb_pix_height = 0;
  uint32_t image_pix_width = 0;
  uint32_t image_pix_height = 0;
  uint32_t image_bit_depth = 0;
  uint32_t parent_object = 0;
  uint16_t association_type = 0;
  uint32_t association_desc = 0;
  uint32_t sequence_number = 0;
  std::string filename;
  std::string capture_date;  // "YYYYMMDDThhmmss[.s]"
  std::string modification_date;
  std::string keywords;

  friend bool operator==(const ObjectInfo&, const ObjectInfo&) = default;
};

std::vector<uint8_t> EncodeDeviceInfo(const DeviceInfo& info);
StatusOr<DeviceInfo> DecodeDeviceInfo(std::span<const uint8_t> bytes);
std::vector<uint8_t> EncodeObjectInfo(const ObjectInfo& info);
StatusOr<ObjectInfo> DecodeObjectInfo(std::span<const uint8_t> bytes);

}  // namespace px::ptp

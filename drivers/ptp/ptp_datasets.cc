#include "drivers/ptp/ptp_datasets.h"

#include <algorithm>

#include "drivers/ptp/ptp_bytes.h"

namespace px::ptp {

bool DeviceInfo::SupportsOperation(uint16_t code) const {
  return std::find(operations_supported.begin(), operations_supported.end(), code) != operations_supported.end();
}

bool DeviceInfo::SupportsProperty(uint16_t code) const {
  return std::find(device_properties_supported.begin(), device_properties_supported.end(), code) !=
         device_properties_supported.end();
}

std::vector<uint8_t> EncodeDeviceInfo(const DeviceInfo& info) {
  ByteWriter out;
  out.U16(info.standard_version);
  out.U32(info.vendor_extension_id);
  out.U16(info.vendor_extension_version);
  out.String(info.vendor_extension_desc);
  out.U16(info.functional_mode);
  out.U16Array(info.operations_supported);
  out.U16Array(info.events_supported);
  out.U16Array(info.device_properties_supported);
  out.U16Array(info.capture_formats);
  out.U16Array(info.image_formats);
  out.String(info.manufacturer);
  out.String(info.model);
  out.String(info.device_version);
  out.String(info.serial_number);
  return std::move(out).Take();
}

StatusOr<DeviceInfo> DecodeDeviceInfo(std::span<const uint8_t> bytes) {
  ByteReader in(bytes, "DeviceInfo");
  DeviceInfo info;
  PX_ASSIGN_OR_RETURN(info.standard_version, in.U16("StandardVersion"));
  PX_ASSIGN_OR_RETURN(info.vendor_extension_id, in.U32("VendorExtensionID"));
  PX_ASSIGN_OR_RETURN(info.vendor_extension_version, in.U16("VendorExtensionVersion"));
  PX_ASSIGN_OR_RETURN(info.vendor_extension_desc, in.String("VendorExtensionDesc"));
  PX_ASSIGN_OR_RETURN(info.functional_mode, in.U16("FunctionalMode"));
  PX_ASSIGN_OR_RETURN(info.operations_supported, in.U16Array("OperationsSupported"));
  PX_ASSIGN_OR_RETURN(info.events_supported, in.U16Array("EventsSupported"));
  PX_ASSIGN_OR_RETURN(info.device_properties_supported, in.U16Array("DevicePropertiesSupported"));
  PX_ASSIGN_OR_RETURN(info.capture_formats, in.U16Array("CaptureFormats"));
  PX_ASSIGN_OR_RETURN(info.image_formats, in.U16Array("ImageFormats"));
  PX_ASSIGN_OR_RETURN(info.manufacturer, in.String("Manufacturer"));
  PX_ASSIGN_OR_RETURN(info.model, in.String("Model"));
  PX_ASSIGN_OR_RETURN(info.device_version, in.String("DeviceVersion"));
  PX_ASSIGN_OR_RETURN(info.serial_number, in.String("SerialNumber"));
  // Trailing bytes are tolerated: vendors append fields.
  return info;
}

std::vector<uint8_t> EncodeObjectInfo(const ObjectInfo& info) {
  ByteWriter out;
  out.U32(info.storage_id);
  out.U16(info.object_format);
  out.U16(info.protection_status);
  out.U32(info.object_compressed_size);
  out.U16(info.thumb_format);
  out.U32(info.thumb_compressed_size);
  out.U32(info.thumb_pix_width);
  out.U32(info.thumb_pix_height);
  out.U32(info.image_pix_width);
  out.U32(info.image_pix_height);
  out.U32(info.image_bit_depth);
  out.U32(info.parent_object);
  out.U16(info.association_type);
  out.U32(info.association_desc);
  out.U32(info.sequence_number);
  out.String(info.filename);
  out.String(info.capture_date);
  out.String(info.modification_date);
  out.String(info.keywords);
  return std::move(out).Take();
}

StatusOr<ObjectInfo> DecodeObjectInfo(std::span<const uint8_t> bytes) {
  ByteReader in(bytes, "ObjectInfo");
  ObjectInfo info;
  PX_ASSIGN_OR_RETURN(info.storage_id, in.U32("StorageID"));
  PX_ASSIGN_OR_RETURN(info.object_format, in.U16("ObjectFormat"));
  PX_ASSIGN_OR_RETURN(info.protection_status, in.U16("ProtectionStatus"));
  PX_ASSIGN_OR_RETURN(info.object_compressed_size, in.U32("ObjectCompressedSize"));
  PX_ASSIGN_OR_RETURN(info.thumb_format, in.U16("ThumbFormat"));
  PX_ASSIGN_OR_RETURN(info.thumb_compressed_size, in.U32("ThumbCompressedSize"));
  PX_ASSIGN_OR_RETURN(info.thumb_pix_width, in.U32("ThumbPixWidth"));
  PX_ASSIGN_OR_RETURN(info.thumb_pix_height, in.U32("ThumbPixHeight"));
  PX_ASSIGN_OR_RETURN(info.image_pix_width, in.U32("ImagePixWidth"));
  PX_ASSIGN_OR_RETURN(info.image_pix_height, in.U32("ImagePixHeight"));
  PX_ASSIGN_OR_RETURN(info.image_bit_depth, in.U32("ImageBitDepth"));
  PX_ASSIGN_OR_RETURN(info.parent_object, in.U32("ParentObject"));
  PX_ASSIGN_OR_RETURN(info.association_type, in.U16("AssociationType"));
  PX_ASSIGN_OR_RETURN(info.association_desc, in.U32("AssociationDesc"));
  PX_ASSIGN_OR_RETURN(info.sequence_number, in.U32("SequenceNumber"));
  PX_ASSIGN_OR_RETURN(info.filename, in.String("Filename"));
  PX_ASSIGN_OR_RETURN(info.capture_date, in.String("CaptureDate"));
  PX_ASSIGN_OR_RETURN(info.modification_date, in.String("ModificationDate"));
  PX_ASSIGN_OR_RETURN(info.keywords, in.String("Keywords"));
  return info;
}

}  // namespace px::ptp

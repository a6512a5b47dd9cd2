// PTP (ISO 15740 / PIMA 15740) codes this initiator uses, and their names for error messages.
#pragma once

#include <cstdint>
#include <string>

namespace px::ptp {

// Container types (the 16-bit field after the length).
enum class ContainerType : uint16_t {
  kCommand = 1,
  kData = 2,
  kResponse = 3,
  kEvent = 4,
};

namespace op {
inline constexpr uint16_t kGetDeviceInfo = 0x1001;
inline constexpr uint16_t kOpenSession = 0x1002;
inline constexpr uint16_t kCloseSession = 0x1003;
inline constexpr uint16_t kGetStorageIds = 0x1004;
inline constexpr uint16_t kGetObjectInfo = 0x1008;
inline constexpr uint16_t kGetObject = 0x1009;
inline constexpr uint16_t kDeleteObject = 0x100B;
inline constexpr uint16_t kInitiateCapture = 0x100E;
inline constexpr uint16_t kGetDevicePropDesc = 0x1014;
inline constexpr uint16_t kGetDevicePropValue = 0x1015;
}  // namespace op

namespace rc {
inline constexpr uint16_t kOk = 0x2001;
inline constexpr uint16_t kGeneralError = 0x2002;
inline constexpr uint16_t kSessionNotOpen = 0x2003;
inline constexpr uint16_t kInvalidTransactionId = 0x2004;
inline constexpr uint16_t kOperationNotSupported = 0x2005;
inline constexpr uint16_t kParameterNotSupported = 0x2006;
inline constexpr uint16_t kIncompleteTransfer = 0x2007;
inline constexpr uint16_t kInvalidStorageId = 0x2008;
inline constexpr uint16_t kInvalidObjectHandle = 0x2009;
inline constexpr uint16_t kDevicePropNotSupported = 0x200A;
inline constexpr uint16_t kStoreFull = 0x200C;
inline constexpr uint16_t kAccessDenied = 0x200F;
inline constexpr uint16_t kStoreNotAvailable = 0x2013;
inline constexpr uint16_t kCaptureAlreadyTerminated = 0x2018;
inline constexpr uint16_t kDeviceBusy = 0x2019;
inline constexpr uint16_t kInvalidParameter = 0x201D;
inline constexpr uint16_t kSessionAlreadyOpen = 0x201E;
inline constexpr uint16_t kTransactionCancelled = 0x201F;
}  // namespace rc

namespace ev {
inline constexpr uint16_t kCancelTransaction = 0x4001;
inline constexpr uint16_t kObjectAdded = 0x4002;
inline constexpr uint16_t kDevicePropChanged = 0x4006;
inline constexpr uint16_t kStoreFull = 0x400A;
inline constexpr uint16_t kDeviceReset = 0x400B;
inline constexpr uint16_t kCaptureComplete = 0x400D;
}  // namespace ev

namespace fmt {
inline constexpr uint16_t kUndefined = 0x3000;
inline constexpr uint16_t kAssociation = 0x3001;
inline constexpr uint16_t kExifJpeg = 0x3801;
}  // namespace fmt

namespace prop {
inline constexpr uint16_t kImageSize = 0x5003;  // a PTP string "WIDTHxHEIGHT"
}  // namespace prop

// "GetObject (0x1009)", "DeviceBusy (0x2019)", "ObjectAdded (0x4002)"; unknown codes as hex.
std::string OperationName(uint16_t code);
std::string ResponseName(uint16_t code);
std::string EventName(uint16_t code);
std::string Hex16(uint16_t value);  // "0x2019"

}  // namespace px::ptp

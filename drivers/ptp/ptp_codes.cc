#include "drivers/ptp/ptp_codes.h"

#include <cstdio>

namespace px::ptp {
namespace {

std::string Named(const char* name, uint16_t code) {
  return name ? std::string(name) + " (" + Hex16(code) + ")" : "unknown (" + Hex16(code) + ")";
}

}  // namespace

std::string Hex16(uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof(text), "0x%04X", value);
  return text;
}

std::string OperationName(uint16_t code) {
  const char* name = nullptr;
  switch (code) {
    case op::kGetDeviceInfo:
      name = "GetDeviceInfo";
      break;
    case op::kOpenSession:
      name = "OpenSession";
      break;
    case op::kCloseSession:
      name = "CloseSession";
      break;
    case op::kGetStorageIds:
      name = "GetStorageIDs";
      break;
    case op::kGetObjectInfo:
      name = "GetObjectInfo";
      break;
    case op::kGetObject:
      name = "GetObject";
      break;
    case op::kDeleteObject:
      name = "DeleteObject";
      break;
    case op::kInitiateCapture:
      name = "InitiateCapture";
      break;
    case op::kGetDevicePropDesc:
      name = "GetDevicePropDesc";
      break;
    case op::kGetDevicePropValue:
      name = "GetDevicePropValue";
      break;
    default:
      break;
  }
  return Named(name, code);
}

std::string ResponseName(uint16_t code) {
  const char* name = nullptr;
  switch (code) {
    case rc::kOk:
      name = "OK";
      break;
    case rc::kGeneralError:
      name = "GeneralError";
      break;
    case rc::kSessionNotOpen:
      name = "SessionNotOpen";
      break;
    case rc::kInvalidTransactionId:
      name = "InvalidTransactionID";
      break;
    case rc::kOperationNotSupported:
      name = "OperationNotSupported";
      break;
    case rc::kParameterNotSupported:
      name = "ParameterNotSupported";
      break;
    case rc::kIncompleteTransfer:
      name = "IncompleteTransfer";
      break;
    case rc::kInvalidStorageId:
      name = "InvalidStorageID";
      break;
    case rc::kInvalidObjectHandle:
      name = "InvalidObjectHandle";
      break;
    case rc::kDevicePropNotSupported:
      name = "DevicePropNotSupported";
      break;
    case rc::kStoreFull:
      name = "StoreFull";
      break;
    case rc::kAccessDenied:
      name = "AccessDenied";
      break;
    case rc::kStoreNotAvailable:
      name = "StoreNotAvailable";
      break;
    case rc::kCaptureAlreadyTerminated:
      name = "CaptureAlreadyTerminated";
      break;
    case rc::kDeviceBusy:
      name = "DeviceBusy";
      break;
    case rc::kInvalidParameter:
      name = "InvalidParameter";
      break;
    case rc::kSessionAlreadyOpen:
      name = "SessionAlreadyOpen";
      break;
    case rc::kTransactionCancelled:
      name = "TransactionCancelled";
      break;
    default:
      break;
  }
  return Named(name, code);
}

std::string EventName(uint16_t code) {
  const char* name = nullptr;
  switch (code) {
    case ev::kCancelTransaction:
      name = "CancelTransaction";
      break;
    case ev::kObjectAdded:
      name = "ObjectAdded";
      break;
    case ev::kDevicePropChanged:
      name = "DevicePropChanged";
      break;
    case ev::kStoreFull:
      name = "StoreFull";
      break;
    case ev::kDeviceReset:
      name = "DeviceReset";
      break;
    case ev::kCaptureComplete:
      name = "CaptureComplete";
      break;
    default:
      break;
  }
  return Named(name, code);
}

}  // namespace px::ptp

#include "drivers/ptp/ptp_session.h"

#include <algorithm>
#include <thread>

#include "drivers/ptp/ptp_bytes.h"
#include "pipeline/core/log.h"

namespace px::ptp {

using std::chrono::milliseconds;
using std::chrono::steady_clock;

namespace {

// A camera may put a zero-length packet after a data phase that filled whole packets.
constexpr int kMaxZeroLengthPackets = 3;
constexpr size_t kEventBytes = 64;

}  // namespace

Status SessionOptions::Validate() const {
  if (transfer_timeout.count() <= 0 || transfer_timeout.count() > 600000) {
    return InvalidArgumentError("ptp.transfer_timeout: " + std::to_string(transfer_timeout.count()) +
                                " ms is not in (0, 600000]");
  }
  if (busy_retries < 0 || busy_retries > 100) {
    return InvalidArgumentError("ptp.busy_retries: " + std::to_string(busy_retries) + " is not in [0, 100]");
  }
  if (bulk_chunk_bytes < 512) {
    return InvalidArgumentError("ptp.bulk_chunk_bytes: " + std::to_string(bulk_chunk_bytes) + " is below 512");
  }
  return OkStatus();
}

StatusCode ResponseStatusCode(uint16_t response_code) {
  switch (response_code) {
    case rc::kDeviceBusy:
    case rc::kStoreNotAvailable:
      return StatusCode::kUnavailable;
    case rc::kStoreFull:
      return StatusCode::kResourceExhausted;
    case rc::kOperationNotSupported:
      return StatusCode::kUnimplemented;
    case rc::kInvalidObjectHandle:
      return StatusCode::kNotFound;
    case rc::kParameterNotSupported:
    case rc::kInvalidParameter:
    case rc::kInvalidStorageId:
      return StatusCode::kInvalidArgument;
    default:
      return StatusCode::kFailedPrecondition;
  }
}

PtpSession::PtpSession(std::unique_ptr<PtpTransport> transport, SessionOptions options)
    : transport_(std::move(transport)), options_(options) {}

PtpSession::~PtpSession() {
  if (open_ && !device_gone_) (void)CloseSession();
}

std::string PtpSession::Where(uint16_t operation) const {
  return "PTP " + OperationName(operation) + " on " + transport_->DeviceName();
}

Status PtpSession::Track(Status status) {
  if (status.code() == StatusCode::kUnavailable) device_gone_ = true;
  return status;
}

StatusOr<std::vector<uint8_t>> PtpSession::ReadContainerBytes(const std::string& where, int* transfers) {
  const size_t packet = std::max<size_t>(transport_->MaxPacketBytes(), 1);
  const size_t chunk = std::max(packet, options_.bulk_chunk_bytes / packet * packet);
  std::vector<uint8_t> bytes;
  for (int zlp = 0;; ++zlp) {
    auto first = transport_->BulkIn(chunk, options_.transfer_timeout);
    if (!first.ok()) return Track(first.status()).WithContext(where);
    ++*transfers;
    if (!first->empty()) {
      bytes = std::move(first).value();
      break;
    }
    if (zlp == kMaxZeroLengthPackets) return DataLossError(where + ": only zero-length packets from the camera");
  }
  PX_ASSIGN_OR_RETURN(ContainerHeader header, DecodeContainerHeader(bytes, where));
  while (bytes.size() < header.length) {
    // A short packet ends a transfer, so a data phase larger than one transfer takes several.
    const size_t left = header.length - bytes.size();
    const size_t want = std::min(chunk, (left + packet - 1) / packet * packet);
    auto more = transport_->BulkIn(want, options_.transfer_timeout);
    if (!more.ok()) {
      return Track(more.status())
          .WithContext(where + ": data phase after " + std::to_string(bytes.size()) + " of " +
                       std::to_string(header.length) + " bytes");
    }
    ++*transfers;
    if (more->empty()) {
      return DataLossError(where + ": data phase ended at " + std::to_string(bytes.size()) + " of " +
                           std::to_string(header.length) + " bytes the container announced");
    }
    bytes.insert(bytes.end(), more->begin(), more->end());
  }
  if (bytes.size() > header.length) {
    return DataLossError(where + ": field length: container says " + std::to_string(header.length) +
                         " bytes, the transfer carried " + std::to_string(bytes.size()));
  }
  return bytes;
}

StatusOr<PtpSession::Result> PtpSession::TransactOnce(uint16_t operation,
                                                      const std::vector<uint32_t>& params,
                                                      bool data_in) {
  const std::string where = Where(operation);
  if (device_gone_) return UnavailableError(where + ": the camera has been disconnected");
  Container command;
  command.type = ContainerType::kCommand;
  command.code = operation;
  command.transaction_id = next_transaction_id_;
  command.params = params;
  // OpenSession is transaction 0 and numbering restarts at 1 inside the session.
  next_transaction_id_ = operation == op::kOpenSession ? 1 : next_transaction_id_ + 1;
  PX_ASSIGN_OR_RETURN(std::vector<uint8_t> command_bytes, EncodeContainer(command));
  if (Status sent = transport_->BulkOut(command_bytes, options_.transfer_timeout); !sent.ok()) {
    return Track(sent).WithContext(where + ": sending the command");
  }

  Result result;
  PX_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes, ReadContainerBytes(where, &result.data_transfers));
  PX_ASSIGN_OR_RETURN(Container first, DecodeContainer(bytes, where));
  if (first.type == ContainerType::kData) {
    if (!data_in) return DataLossError(where + ": unexpected data phase from the camera");
    if (first.code != operation || first.transaction_id != command.transaction_id) {
      return DataLossError(where + ": data container for " + OperationName(first.code) + " transaction " +
                           std::to_string(first.transaction_id) + ", want transaction " +
                           std::to_string(command.transaction_id));
    }
    result.data = std::move(first.payload);
    int response_transfers = 0;
    PX_ASSIGN_OR_RETURN(bytes, ReadContainerBytes(where + " response", &response_transfers));
    PX_ASSIGN_OR_RETURN(first, DecodeContainer(bytes, where + " response"));
  } else {
    result.data_transfers = 0;
  }
  last_data_transfers_ = result.data_transfers;
  if (first.type != ContainerType::kResponse) {
    return DataLossError(where + ": field type: got a " + ContainerTypeName(first.type) +
                         " container where the response belongs");
  }
  if (first.transaction_id != command.transaction_id) {
    return DataLossError(where + ": field transaction id: response for transaction " +
                         std::to_string(first.transaction_id) + ", want " + std::to_string(command.transaction_id));
  }
  result.response = std::move(first);
  return result;
}

StatusOr<PtpSession::Result> PtpSession::Transact(uint16_t operation, std::vector<uint32_t> params, bool data_in) {
  milliseconds backoff = options_.busy_backoff;
  for (int attempt = 0;; ++attempt) {
    PX_ASSIGN_OR_RETURN(Result result, TransactOnce(operation, params, data_in));
    const uint16_t code = result.response.code;
    if (code == rc::kOk) return result;
    if (code == rc::kDeviceBusy && attempt < options_.busy_retries) {
      Logger("ptp")->debug("{}: DeviceBusy, retrying in {} ms", Where(operation), backoff.count());
      std::this_thread::sleep_for(backoff);
      backoff *= 2;
      continue;
    }
    std::string message = Where(operation) + ": camera answered " + ResponseName(code);
    if (code == rc::kDeviceBusy) message += " " + std::to_string(attempt + 1) + " times";
    return Status(ResponseStatusCode(code), message);
  }
}

StatusOr<DeviceInfo> PtpSession::GetDeviceInfo() {
  PX_ASSIGN_OR_RETURN(Result result, Transact(op::kGetDeviceInfo, {}, true));
  auto info = DecodeDeviceInfo(result.data);
  if (!info.ok()) return info.status().WithContext(Where(op::kGetDeviceInfo));
  return info;
}

Status PtpSession::OpenSession(uint32_t session_id) {
  next_transaction_id_ = 0;
  auto result = Transact(op::kOpenSession, {session_id}, false);
  if (!result.ok() && result.status().message().find(ResponseName(rc::kSessionAlreadyOpen)) != std::string::npos) {
    // Left open by an earlier run that did not close it: close it and start afresh.
    Logger("ptp")->info("{}: a session was already open; closing it", transport_->DeviceName());
    (void)Transact(op::kCloseSession, {}, false);
    next_transaction_id_ = 0;
    result = Transact(op::kOpenSession, {session_id}, false);
  }
  if (!result.ok()) return result.status();
  open_ = true;
  return OkStatus();
}

Status PtpSession::CloseSession() {
  if (!open_) return OkStatus();
  open_ = false;
  auto result = Transact(op::kCloseSession, {}, false);
  return result.ok() ? OkStatus() : result.status();
}

StatusOr<uint32_t> PtpSession::InitiateCapture() {
  PX_ASSIGN_OR_RETURN(Result result, Transact(op::kInitiateCapture, {0, 0}, false));
  return result.response.transaction_id;
}

StatusOr<Container> PtpSession::WaitForEvent(uint16_t code, steady_clock::time_point deadline) {
  const std::string where = "PTP event " + EventName(code) + " from " + transport_->DeviceName();
  const auto start = steady_clock::now();
  while (true) {
    const auto left = std::chrono::ceil<milliseconds>(deadline - steady_clock::now());
    if (left.count() <= 0) {
      const auto waited = std::chrono::duration_cast<milliseconds>(steady_clock::now() - start);
      return DeadlineExceededError(where + ": not received within " + std::to_string(waited.count()) + " ms");
    }
    auto bytes = transport_->InterruptIn(kEventBytes, left);
    if (!bytes.ok()) {
      if (bytes.status().code() == StatusCode::kDeadlineExceeded) continue;
      return Track(bytes.status()).WithContext(where);
    }
    if (bytes->empty()) continue;
    PX_ASSIGN_OR_RETURN(Container event, DecodeContainer(*bytes, where));
    if (event.type != ContainerType::kEvent) {
      return DataLossError(where + ": field type: a " + ContainerTypeName(event.type) +
                           " container on the interrupt pipe");
    }
    if (event.code == code) return event;
    Logger("ptp")->debug("{}: skipping event {}", transport_->DeviceName(), EventName(event.code));
  }
}

StatusOr<ObjectInfo> PtpSession::GetObjectInfo(uint32_t handle) {
  PX_ASSIGN_OR_RETURN(Result result, Transact(op::kGetObjectInfo, {handle}, true));
  auto info = DecodeObjectInfo(result.data);
  if (!info.ok()) return info.status().WithContext(Where(op::kGetObjectInfo));
  return info;
}

StatusOr<std::vector<uint8_t>> PtpSession::GetObject(uint32_t handle) {
  PX_ASSIGN_OR_RETURN(Result result, Transact(op::kGetObject, {handle}, true));
  return std::move(result.data);
}

Status PtpSession::DeleteObject(uint32_t handle) {
  auto result = Transact(op::kDeleteObject, {handle, 0}, false);
  return result.ok() ? OkStatus() : result.status();
}

StatusOr<std::string> PtpSession::GetDevicePropString(uint16_t property) {
  PX_ASSIGN_OR_RETURN(Result result, Transact(op::kGetDevicePropValue, {property}, true));
  ByteReader in(result.data, Where(op::kGetDevicePropValue) + " property " + Hex16(property));
  return in.String("value");
}

}  // namespace px::ptp

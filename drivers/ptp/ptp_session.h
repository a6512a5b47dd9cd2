// A PTP session over a transport: one transaction at a time (command, optional data-in phase,
// response), event waits on the interrupt pipe, and the handful of operations a tethered
// capture needs. Every non-OK response becomes an error naming the operation, the response code
// and the device; DeviceBusy is retried a few times first.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drivers/ptp/ptp_container.h"
#include "drivers/ptp/ptp_datasets.h"
#include "drivers/ptp/ptp_transport.h"

namespace px::ptp {

struct SessionOptions {
  std::chrono::milliseconds transfer_timeout{5000};  // per bulk transfer, (0, 600000]
  int busy_retries = 4;                              // extra tries after DeviceBusy, [0, 100]
  std::chrono::milliseconds busy_backoff{50};        // wait before each retry, doubled each time
  size_t bulk_chunk_bytes = 256 * 1024;              // bytes per bulk-in transfer of a data phase

  Status Validate() const;
};

// Maps a response code to a status code: DeviceBusy and StoreNotAvailable UNAVAILABLE,
// StoreFull RESOURCE_EXHAUSTED, OperationNotSupported UNIMPLEMENTED, InvalidObjectHandle
// NOT_FOUND, parameter errors INVALID_ARGUMENT, the rest FAILED_PRECONDITION.
StatusCode ResponseStatusCode(uint16_t response_code);

class PtpSession {
 public:
  PtpSession(std::unique_ptr<PtpTransport> transport, SessionOptions options);
  ~PtpSession();  // closes the session if it is open (best effort)

  struct Result {
    Container response;
    std::vector<uint8_t> data;  // the data-in phase's payload, if there was one
    int data_transfers = 0;     // bulk-in transfers the data phase took
  };

  // One transaction. `data_in`: the operation has a data-in phase. Retries DeviceBusy.
  StatusOr<Result> Transact(uint16_t operation, std::vector<uint32_t> params, bool data_in);

  StatusOr<DeviceInfo> GetDeviceInfo();
  Status OpenSession(uint32_t session_id = 1);
  Status CloseSession();
  // Starts a capture (storage 0 and format 0: the camera's defaults). Returns its transaction
  // id, which the CaptureComplete event names.
  StatusOr<uint32_t> InitiateCapture();
  // Waits for an event with `code` until `deadline` (steady clock). Other events are logged and
  // skipped. DEADLINE_EXCEEDED names the event and how long it waited.
  StatusOr<Container> WaitForEvent(uint16_t code, std::chrono::steady_clock::time_point deadline);
  StatusOr<ObjectInfo> GetObjectInfo(uint32_t handle);
  StatusOr<std::vector<uint8_t>> GetObject(uint32_t handle);
  Status DeleteObject(uint32_t handle);
  // A string-typed device property (ImageSize "6000x4000").
  StatusOr<std::string> GetDevicePropString(uint16_t property);

  bool is_open() const { return open_; }
  // True once a transfer reported that the device has gone (UNAVAILABLE from the transport).
  bool device_gone() const { return device_gone_; }
  std::string DeviceName() const { return transport_->DeviceName(); }
  int last_data_transfers() const { return last_data_transfers_; }

 private:
  StatusOr<Result> TransactOnce(uint16_t operation, const std::vector<uint32_t>& params, bool data_in);
  StatusOr<std::vector<uint8_t>> ReadContainerBytes(const std::string& where, int* transfers);
  Status Track(Status status);  // notes a vanished device
  std::string Where(uint16_t operation) const;

  std::unique_ptr<PtpTransport> transport_;
  SessionOptions options_;
  uint32_t next_transaction_id_ = 0;
  bool open_ = false;
  bool device_gone_ = false;
  int last_data_transfers_ = 0;
};

}  // namespace px::ptp

// PTP-over-USB containers (PIMA 15740 annex D / USB Still Image Capture Device class):
//   UINT32 length (header included) | UINT16 type | UINT16 code | UINT32 transaction id | payload
// where the payload is up to five UINT32 parameters (command, response; up to three for an
// event) or the dataset bytes of a data phase. Decoding is strict: a container whose length,
// type or parameter count does not add up is a DATA_LOSS error naming the field.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "drivers/ptp/ptp_codes.h"
#include "pipeline/core/status.h"

namespace px::ptp {

inline constexpr size_t kContainerHeaderBytes = 12;
inline constexpr size_t kMaxParams = 5;
inline constexpr size_t kMaxEventParams = 3;

struct ContainerHeader {
  uint32_t length = 0;  // the whole container, header included
  ContainerType type = ContainerType::kCommand;
  uint16_t code = 0;
  uint32_t transaction_id = 0;
};

struct Container {
  ContainerType type = ContainerType::kCommand;
  uint16_t code = 0;
  uint32_t transaction_id = 0;
  std::vector<uint32_t> params;  // command, response, event
  std::vector<uint8_t> payload;  // data

  friend bool operator==(const Container&, const Container&) = default;
};

std::string ContainerTypeName(ContainerType type);  // "command", "data", "response", "event"

// Fails (INVALID_ARGUMENT) on too many parameters, parameters on a data container, or a payload
// on a non-data container.
StatusOr<std::vector<uint8_t>> EncodeContainer(const Container& container);

// The first 12 bytes: checks the type is known and the length at least a header. `where` names
// the transfer in errors ("response to GetObject (0x1009)").
StatusOr<ContainerHeader> DecodeContainerHeader(std::span<const uint8_t> bytes, const std::string& where);

// A whole container: the length field must equal bytes.size().
StatusOr<Container> DecodeContainer(std::span<const uint8_t> bytes, const std::string& where);

}  // namespace px::ptp

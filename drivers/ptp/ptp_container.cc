#include "drivers/ptp/ptp_container.h"

#include "drivers/ptp/ptp_bytes.h"

namespace px::ptp {

std::string ContainerTypeName(ContainerType type) {
  switch (type) {
    case ContainerType::kCommand:
      return "command";
    case ContainerType::kData:
      return "data";
    case ContainerType::kResponse:
      return "response";
    case ContainerType::kEvent:
      return "event";
  }
  return "type " + std::to_string(static_cast<int>(type));
}

StatusOr<std::vector<uint8_t>> EncodeContainer(const Container& container) {
  const bool is_data = container.type == ContainerType::kData;
  const size_t max_params = container.type == ContainerType::kEvent ? kMaxEventParams : kMaxParams;
  if (is_data && !container.params.empty()) {
    return InvalidArgumentError("PTP data container: parameters are not allowed, got " +
                                std::to_string(container.params.size()));
  }
  if (!is_data && !container.payload.empty()) {
    return InvalidArgumentError("PTP " + ContainerTypeName(container.type) +
                                " container: payload bytes are only for data containers");
  }
  if (container.params.size() > max_params) {
    return InvalidArgumentError("PTP " + ContainerTypeName(container.type) +
                                " container: " + std::to_string(container.params.size()) + " parameters, at most " +
                                std::to_string(max_params));
  }
  const size_t length = kContainerHeaderBytes + 4 * container.params.size() + container.payload.size();
  if (length > 0xFFFFFFFFu) return InvalidArgumentError("PTP data container: payload over 4 GiB");
  ByteWriter out;
  out.U32(static_cast<uint32_t>(length));
  out.U16(static_cast<uint16_t>(container.type));
  out.U16(container.code);
  out.U32(container.transaction_id);
  for (uint32_t p : container.params) out.U32(p);
  out.Bytes(container.payload);
  return std::move(out).Take();
}

StatusOr<ContainerHeader> DecodeContainerHeader(std::span<const uint8_t> bytes, const std::string& where) {
  ByteReader in(bytes, "PTP container (" + where + ")");
  ContainerHeader header;
  PX_ASSIGN_OR_RETURN(header.length, in.U32("length"));
  PX_ASSIGN_OR_RETURN(uint16_t type, in.U16("type"));
  PX_ASSIGN_OR_RETURN(header.code, in.U16("code"));
  PX_ASSIGN_OR_RETURN(header.transaction_id, in.U32("transaction id"));
  if (type < 1 || type > 4) {
    return DataLossError("PTP container (" + where + "): field type: " + std::to_string(type) +
                         " is not command (1), data (2), response (3) or event (4)");
  }
  header.type = static_cast<ContainerType>(type);
  if (header.length < kContainerHeaderBytes) {
    return DataLossError("PTP container (" + where + "): field length: " + std::to_string(header.length) +
                         " is shorter than the 12-byte header");
  }
  return header;
}

StatusOr<Container> DecodeContainer(std::span<const uint8_t> bytes, const std::string& where) {
  PX_ASSIGN_OR_RETURN(ContainerHeader header, DecodeContainerHeader(bytes, where));
  const std::string what = "PTP " + ContainerTypeName(header.type) + " container (" + where + ")";
  if (header.length != bytes.size()) {
    return DataLossError(what + ": field length: says " + std::to_string(header.length) + " bytes, got " +
                         std::to_string(bytes.size()));
  }
  Container container;
  container.type = header.type;
  container.code = header.code;
  container.transaction_id = header.transaction_id;
  const auto body = bytes.subspan(kContainerHeaderBytes);
  if (header.type == ContainerType::kData) {
    container.payload.assign(body.begin(), body.end());
    return container;
  }
  const size_t max_params = header.type == ContainerType::kEvent ? kMaxEventParams : kMaxParams;
  if (body.size() % 4 != 0 || body.size() / 4 > max_params) {
    return DataLossError(what + ": field params: " + std::to_string(body.size()) +
                         " bytes is not a whole number of at most " + std::to_string(max_params) +
                         " UINT32 parameters");
  }
  for (size_t i = 0; i < body.size(); i += 4) container.params.push_back(LoadU32(body.data() + i));
  return container;
}

}  // namespace px::ptp

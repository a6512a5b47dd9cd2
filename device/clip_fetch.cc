#include "device/clip_fetch.h"

#include <nlohmann/json.hpp>
#include <span>
#include <system_error>

#include "device/control_protocol.h"
#include "pipeline/core/durable_file.h"
#include "sim/replay/sha256.h"

namespace px::device {

std::string Base64Encode(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint8_t(bytes[i]) << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

StatusOr<nlohmann::json> FetchClipReply(const std::string& id, const std::optional<JobRecord>& record,
                                        bool inline_bytes) {
  if (!record) return NotFoundError("job '" + id + "': no such job");
  if (record->state == JobState::kFailed) {
    return FailedPreconditionError("job " + id + " failed, it has no clip: " + record->error);
  }
  if (record->state != JobState::kDone) {
    return FailedPreconditionError("job " + id + " is " + std::string(JobStateName(record->state)) +
                                   "; its clip is not made yet");
  }
  if (record->clip_path.empty()) return NotFoundError("job " + id + ": its clip is gone: " + record->note);
  std::error_code ec;
  if (std::filesystem::is_directory(record->clip_path, ec)) {
    return FailedPreconditionError("job " + id + ": its clip is a folder of PNG frames (clip.format png), not one "
                                   "file; read the frames from " + record->clip_path);
  }
  const uint64_t size = std::filesystem::file_size(record->clip_path, ec);
  if (ec) return DataLossError("job " + id + ": clip " + record->clip_path + " is missing: " + ec.message());
  if (inline_bytes && size > kMaxInlineClipBytes) {
    return OutOfRangeError("job " + id + ": clip of " + std::to_string(size) + " bytes is over the inline limit of " +
                           std::to_string(kMaxInlineClipBytes) + "; read it from " + record->clip_path);
  }
  StatusOr<std::string> bytes = ReadFileToString(record->clip_path);
  if (!bytes.ok()) return bytes.status().WithContext("job " + id);
  nlohmann::json reply = {
      {"ok", true},
      {"job", id},
      {"path", record->clip_path},
      {"bytes", bytes->size()},
      {"sha256",
       replay::Sha256Hex(std::span(reinterpret_cast<const uint8_t*>(bytes->data()), bytes->size()))},
  };
  if (inline_bytes) reply["data"] = Base64Encode(*bytes);
  return reply;
}

}  // namespace px::device

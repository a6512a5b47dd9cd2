#include "tests/fuzz/fuzz_entry_points.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>

#include "capture/animation_frames.h"
#include "capture/mpo.h"
#include "capture/recording.h"
#include "device/control/control_protocol.h"
#include "drivers/ptp/ptp_container.h"
#include "drivers/ptp/ptp_datasets.h"
#include "pipeline/io/image_file.h"

namespace px::fuzz {
namespace {

namespace fs = std::filesystem;

// A file name the harness may create: what the format allows, so nothing leaves the folder.
bool SafeName(const std::string& name) {
  if (name.empty() || name.size() > 64 || name[0] == '.' || name == "manifest.json") return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') return false;
  }
  return true;
}

void WriteFile(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// One folder per process, emptied for every input.
const fs::path& ScratchDir() {
  static const fs::path dir = [] {
    fs::path path = fs::temp_directory_path() / ("px-fuzz-recording-" + std::to_string(::getpid()));
    fs::create_directories(path);
    return path;
  }();
  return dir;
}

}  // namespace

Status FuzzControlRequest(const uint8_t* data, size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  StatusOr<device::ControlRequest> request = device::ParseControlRequest(line);
  if (!request.ok()) (void)device::ControlErrorReply(request.status());
  return request.status();
}

Status FuzzRecording(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> parts;
  for (size_t start = 0;;) {
    const size_t at = input.find(kFrameSeparator, start);
    parts.push_back(input.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
    if (at == std::string_view::npos) break;
    start = at + sizeof(kFrameSeparator) - 1;
  }
  const fs::path& dir = ScratchDir();
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) fs::remove_all(entry.path(), ec);
  WriteFile(dir / "manifest.json", parts[0]);
  const nlohmann::json manifest = nlohmann::json::parse(parts[0], nullptr, /*allow_exceptions=*/false);
  if (manifest.is_object() && manifest.contains("frames") && manifest["frames"].is_array()) {
    size_t next = 1;
    for (const nlohmann::json& frame : manifest["frames"]) {
      if (next >= parts.size()) break;
      if (!frame.is_object() || !frame.contains("file") || !frame["file"].is_string()) continue;
      const std::string name = frame["file"].get<std::string>();
      if (SafeName(name)) WriteFile(dir / name, parts[next++]);
    }
  }
  return ReadRecording(dir).status();
}

int FuzzPtp(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  StatusOr<ptp::Container> container = ptp::DecodeContainer(bytes, "fuzz");
  int decoded = container.ok() ? 1 : 0;
  decoded += ptp::DecodeDeviceInfo(bytes).ok() ? 1 : 0;
  decoded += ptp::DecodeObjectInfo(bytes).ok() ? 1 : 0;
  if (container.ok() && !container->payload.empty()) {
    decoded += ptp::DecodeDeviceInfo(container->payload).ok() ? 1 : 0;
    decoded += ptp::DecodeObjectInfo(container->payload).ok() ? 1 : 0;
  }
  return decoded;
}

int FuzzPhoto(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  ImageDecodeOptions limits;
  limits.max_pixels = 4e6;
  int decoded = DecodeImageBytes(bytes, "fuzz", limits).ok() ? 1 : 0;
  StatusOr<std::vector<std::vector<uint8_t>>> images = SplitMpo(std::vector<uint8_t>(data, data + size), "fuzz");
  if (images.ok()) {
    bool all = true;
    for (const std::vector<uint8_t>& image : *images) all = DecodeImageBytes(image, "fuzz", limits).ok() && all;
    decoded += all ? 1 : 0;
  }
  const fs::path file = ScratchDir() / "animation";
  WriteFile(file, std::string_view(reinterpret_cast<const char*>(data), size));
  decoded += ReadAnimationFrames(file).ok() ? 1 : 0;
  return decoded;
}

}  // namespace px::fuzz

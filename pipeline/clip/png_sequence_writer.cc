#include "pipeline/clip/png_sequence_writer.h"

#include <cerrno>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "pipeline/io/durable_file.h"

namespace px::clip {
namespace {

// frame_00000.png, frame_00001.png, ...: sorted by name is sorted by time.
std::string FrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%05d.png", index);
  return name;
}

class PngSequenceWriter final : public ClipWriter {
 public:
  PngSequenceWriter(const std::filesystem::path& path, int width, int height, const ClipOptions& options)
      : ClipWriter(ClipFormat::kPng, path, width, height), compression_(options.png_compression) {}

  Status Init() {
    std::error_code ec;
    if (std::filesystem::exists(path(), ec) && !std::filesystem::is_empty(path(), ec)) {
      return Status(StatusCode::kAlreadyExists, "clip " + path().string() + ": the PNG folder exists and is not empty");
    }
    std::filesystem::create_directory(path(), ec);
    if (ec) return ErrnoToStatus(ec.value(), "create folder", path());
    return OkStatus();
  }

 protected:
  Status WriteFrame(const cv::Mat& bgr, int index) override {
    std::vector<uint8_t> bytes;
    try {
      if (!cv::imencode(".png", bgr, bytes, {cv::IMWRITE_PNG_COMPRESSION, compression_})) {
        return InternalError("clip " + path().string() + ": PNG encoding of frame " + std::to_string(index) +
                             " failed");
      }
    } catch (const cv::Exception& e) {
      return InternalError("clip " + path().string() + ": PNG encoding of frame " + std::to_string(index) + ": " +
                           e.what());
    }
    const std::filesystem::path file = path() / FrameName(index);
    std::FILE* out = std::fopen(file.c_str(), "wb");
    if (out == nullptr) return ErrnoToStatus(errno, "create", file, bytes.size());
    const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), out);
    const int write_errno = errno;
    const bool closed = std::fclose(out) == 0;
    if (written != bytes.size() || !closed)
      return ErrnoToStatus(write_errno != 0 ? write_errno : EIO, "write", file, bytes.size());
    return OkStatus();
  }

  // Every frame reaches the disk before the caller renames the folder into place.
  Status FinishClip() override {
    for (int i = 0; i < FramesWritten(); ++i) PX_RETURN_IF_ERROR(FsyncFile(path() / FrameName(i)));
    return FsyncDir(path());
  }

 private:
  int compression_;
};

}  // namespace

StatusOr<std::unique_ptr<ClipWriter>> OpenPngSequenceWriter(const std::filesystem::path& path,
                                                            int width,
                                                            int height,
                                                            const ClipOptions& options) {
  PX_RETURN_IF_ERROR(CheckClipSize(path, width, height, 1, 32767));
  auto writer = std::make_unique<PngSequenceWriter>(path, width, height, options);
  PX_RETURN_IF_ERROR(writer->Init());
  return std::unique_ptr<ClipWriter>(std::move(writer));
}

}  // namespace px::clip

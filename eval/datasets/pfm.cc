#include "eval/datasets/pfm.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>

namespace px::eval {

StatusOr<cv::Mat> ReadPfm(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError(path.string() + ": cannot open");
  std::string magic;
  int width = 0, height = 0;
  double scale = 0;
  in >> magic >> width >> height >> scale;
  if (!in || (magic != "Pf" && magic != "PF")) return DataLossError(path.string() + ": not a PFM file (bad header)");
  if (width <= 0 || height <= 0 || width > 1 << 15 || height > 1 << 15 || scale == 0) {
    return DataLossError(path.string() + ": bad PFM size or scale");
  }
  in.get();  // the single whitespace byte ending the header
  const int channels = magic == "PF" ? 3 : 1;
  cv::Mat image(height, width, channels == 3 ? CV_32FC3 : CV_32F);
  const bool file_little = scale < 0;
  const bool host_little = std::endian::native == std::endian::little;
  const size_t row_bytes = static_cast<size_t>(width) * channels * sizeof(float);
  for (int y = height - 1; y >= 0; --y) {  // stored bottom to top
    in.read(reinterpret_cast<char*>(image.ptr(y)), static_cast<std::streamsize>(row_bytes));
    if (!in) {
      return DataLossError(path.string() + ": truncated: row " + std::to_string(height - 1 - y) + " of " +
                           std::to_string(height) + " is missing");
    }
    if (file_little != host_little) {
      auto* bytes = image.ptr<uint8_t>(y);
      for (size_t i = 0; i < row_bytes; i += 4) {
        std::swap(bytes[i], bytes[i + 3]);
        std::swap(bytes[i + 1], bytes[i + 2]);
      }
    }
  }
  return image;
}

Status WritePfm(const std::filesystem::path& path, const cv::Mat& image) {
  if (image.type() != CV_32F && image.type() != CV_32FC3) {
    return InvalidArgumentError(path.string() + ": PFM holds CV_32F or CV_32FC3 images only");
  }
  std::ofstream out(path, std::ios::binary);
  if (!out) return NotFoundError(path.string() + ": cannot create");
  out << (image.channels() == 3 ? "PF" : "Pf") << "\n" << image.cols << " " << image.rows << "\n-1\n";
  static_assert(std::endian::native == std::endian::little, "WritePfm writes host floats as little endian");
  for (int y = image.rows - 1; y >= 0; --y) {
    out.write(reinterpret_cast<const char*>(image.ptr(y)), static_cast<std::streamsize>(image.cols * image.elemSize()));
  }
  if (!out) return DataLossError(path.string() + ": write failed");
  return OkStatus();
}

}  // namespace px::eval

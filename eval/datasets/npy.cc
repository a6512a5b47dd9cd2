#include "eval/datasets/npy.h"

#include <cstring>
#include <fstream>
#include <regex>

namespace px::eval {

StatusOr<NpyArray> ReadNpyFloat64(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFoundError(path.string() + ": cannot open");
  char magic[8];
  in.read(magic, 8);
  if (!in || std::memcmp(magic, "\x93NUMPY", 6) != 0) return DataLossError(path.string() + ": not a .npy file");
  const int major = static_cast<unsigned char>(magic[6]);
  uint32_t header_length = 0;
  if (major == 1) {
    uint8_t bytes[2];
    in.read(reinterpret_cast<char*>(bytes), 2);
    header_length = bytes[0] | (bytes[1] << 8);
  } else if (major == 2 || major == 3) {
    uint8_t bytes[4];
    in.read(reinterpret_cast<char*>(bytes), 4);
    header_length = bytes[0] | (bytes[1] << 8) | (bytes[2] << 16) | (static_cast<uint32_t>(bytes[3]) << 24);
  } else {
    return DataLossError(path.string() + ": .npy format version " + std::to_string(major) + " is not supported");
  }
  std::string header(header_length, '\0');
  in.read(header.data(), header_length);
  if (!in) return DataLossError(path.string() + ": truncated header");
  if (header.find("'descr': '<f8'") == std::string::npos) {
    return InvalidArgumentError(path.string() + ": descr is not '<f8' (little-endian float64): " + header);
  }
  if (header.find("'fortran_order': False") == std::string::npos) {
    return InvalidArgumentError(path.string() + ": fortran_order arrays are not supported");
  }
  std::smatch match;
  if (!std::regex_search(header, match, std::regex("'shape': \\(([0-9, ]*)\\)"))) {
    return DataLossError(path.string() + ": no shape in header");
  }
  NpyArray array;
  size_t count = 1;
  const std::string dims = match[1];
  const std::regex number("[0-9]+");
  for (std::sregex_iterator it(dims.begin(), dims.end(), number), end; it != end; ++it) {
    array.shape.push_back(std::stoul(it->str()));
    count *= array.shape.back();
  }
  if (array.shape.empty() || count > (1u << 28)) return DataLossError(path.string() + ": bad shape (" + dims + ")");
  array.values.resize(count);
  in.read(reinterpret_cast<char*>(array.values.data()), static_cast<std::streamsize>(count * sizeof(double)));
  if (!in) return DataLossError(path.string() + ": truncated: fewer than " + std::to_string(count) + " values");
  return array;
}

}  // namespace px::eval

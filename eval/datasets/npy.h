// NumPy .npy arrays of little-endian float64 in C order (LLFF's poses_bounds.npy).
#pragma once

#include <filesystem>
#include <vector>

#include "pipeline/core/status.h"

namespace px::eval {

struct NpyArray {
  std::vector<size_t> shape;
  std::vector<double> values;  // C (row-major) order
};

// Reads format versions 1 to 3 with dtype '<f8' and fortran_order False; other arrays are
// refused with an error naming the file and the field.
StatusOr<NpyArray> ReadNpyFloat64(const std::filesystem::path& path);

}  // namespace px::eval

// libFuzzer target: photo (fuzz_entry_points.h). Built only with clang and PX_BUILD_FUZZERS;
// run by scripts/fuzz, corpus in tests/fuzz/corpus/photo/.
#include "tests/fuzz/fuzz_entry_points.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)px::fuzz::FuzzPhoto(data, size);
  return 0;
}

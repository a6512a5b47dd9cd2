// libFuzzer target: control_request (fuzz_entry_points.h). Built only with clang and PX_BUILD_FUZZERS;
// run by scripts/fuzz, corpus in tests/fuzz/corpus/control_request/.
#include "tests/fuzz/fuzz_entry_points.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  (void)px::fuzz::FuzzControlRequest(data, size);
  return 0;
}

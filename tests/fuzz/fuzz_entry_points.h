// The inputs the fuzzers throw at the code that reads untrusted bytes, one entry point per
// target, shared by the libFuzzer targets (clang, PX_BUILD_FUZZERS) and corpus_replay_test (any
// compiler, always in CI) so the kept corpora are replayed on every build. Each returns whatever
// the input (what it returns lets the replay test check that valid seeds are accepted); a crash,
// sanitizer report or uncaught exception is the finding.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pipeline/core/status.h"

namespace px::fuzz {

// One control request line: ParseControlRequest, then the error reply a client would get.
Status FuzzControlRequest(const uint8_t* data, size_t size);

// A recording folder: the input is manifest.json, then each frame file after a line
// "--px-frame--" (kFrameSeparator), written under the names the manifest gives (in frame order);
// then ReadRecording.
inline constexpr char kFrameSeparator[] = "\n--px-frame--\n";
Status FuzzRecording(const uint8_t* data, size_t size);

// PTP bytes from a camera: a container (header and parameters or payload), and the same bytes
// (and a data container's payload) as a DeviceInfo and an ObjectInfo dataset. Returns how many
// of those decoded.
int FuzzPtp(const uint8_t* data, size_t size);

// A photo file a user imports: the bytes decoded as one image (DecodeImageBytes, its header checked
// first, with a limit of 4 MP so that a claimed size stays cheap), split as an MPO with each image
// decoded, and read as an animated GIF or WebP (ReadAnimationFrames, from a scratch file). Returns
// how many of those three decoded.
int FuzzPhoto(const uint8_t* data, size_t size);

}  // namespace px::fuzz

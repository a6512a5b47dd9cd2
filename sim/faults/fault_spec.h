// One injected camera failure, and its JSON form (the daemon's config carries a list of them as
// source.faults):
//   {"kind":"truncate","capture":2,"keep":0.6}
//   {"kind":"vanish","capture":3,"forever":true}
// `capture` counts calls of FrameSource::Next through the wrapper, from 1; 0 fires on every one.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/pixel_format.h"
#include "pipeline/core/status.h"

namespace px {

enum class FaultKind {
  kTruncate,  // the view's buffer arrives short (only `keep` of its bytes): frame status corrupt
  kGarble,    // `bytes` bytes of the view change; `flagged`: the driver marks the buffer corrupt
  kDrop,      // image set: the image never arrives (dropped); lattice: tile `view` is blank, as
              // behind a covered or dead lens (one sensor readout cannot lose one tile)
  kReorder,   // image set: the images arrive in a different order (each keeps its sequence)
  kReformat,  // the view comes in another pixel format and/or size than was granted
  kStall,     // no frame set: Next waits its whole timeout, then DEADLINE_EXCEEDED
  kVanish,    // the camera disconnects: UNAVAILABLE now and after, until Configure (or forever)
};

std::string_view FaultKindName(FaultKind kind);  // "truncate", "garble", ...
StatusOr<FaultKind> ParseFaultKind(std::string_view name);

struct FaultSpec {
  FaultKind kind = FaultKind::kTruncate;
  int capture = 1;      // the Next() call it fires on, from 1; 0 = every call
  int view = 0;         // image of an image set; on a lattice: the tile (drop) or the frame, 0 (others)
  double keep = 0.5;    // truncate: fraction of the bytes that arrive, [0, 1)
  int bytes = 64;       // garble: bytes changed, >= 1
  bool flagged = true;  // garble: the driver flags the buffer (status corrupt); false: silent damage
  std::optional<PixelFormat> pixel_format;  // reformat: the format delivered (absent: unchanged)
  int width = 0;                            // reformat: the size delivered, 0 = unchanged
  int height = 0;
  bool forever = false;  // vanish: Configure fails too; the camera never comes back
  uint64_t seed = 1;     // garble offsets and values, reorder permutation

  // Ranges and combinations; errors start with `field` ("source.faults[2].keep: 1.5 is not in [0, 1)").
  Status Validate(const std::string& field = "fault") const;
};

// Only the fields that apply to the kind are accepted; unknown ones are errors naming `field`.
StatusOr<FaultSpec> FaultSpecFromJson(const nlohmann::json& j, const std::string& field = "fault");
// The fields that apply to the kind, every one written.
nlohmann::json FaultSpecToJson(const FaultSpec& spec);

// A list of specs: field[i] in errors.
StatusOr<std::vector<FaultSpec>> FaultSpecsFromJson(const nlohmann::json& j, const std::string& field = "faults");
nlohmann::json FaultSpecsToJson(const std::vector<FaultSpec>& specs);

// "truncate at capture 2 (view 0, keep 0.6)", for logs.
std::string DescribeFault(const FaultSpec& spec);

}  // namespace px

#include "pipeline/core/frame_set.h"

namespace px {

std::string_view FrameSetKindName(FrameSetKind kind) {
  return kind == FrameSetKind::kLatticeFrame ? "lattice_frame" : "image_set";
}

StatusOr<FrameSetKind> ParseFrameSetKind(std::string_view name) {
  if (name == "lattice_frame") return FrameSetKind::kLatticeFrame;
  if (name == "image_set") return FrameSetKind::kImageSet;
  return InvalidArgumentError("frame set kind '" + std::string(name) + "' is not lattice_frame or image_set");
}

std::string_view FrameStatusName(FrameStatus status) {
  switch (status) {
    case FrameStatus::kOk:
      return "ok";
    case FrameStatus::kCorrupt:
      return "corrupt";
    case FrameStatus::kDropped:
      return "dropped";
    case FrameStatus::kWrongFormat:
      return "wrong_format";
  }
  return "ok";
}

StatusOr<FrameStatus> ParseFrameStatus(std::string_view name) {
  for (auto s : {FrameStatus::kOk, FrameStatus::kCorrupt, FrameStatus::kDropped, FrameStatus::kWrongFormat}) {
    if (FrameStatusName(s) == name) return s;
  }
  return InvalidArgumentError("frame status '" + std::string(name) +
                              "' is not one of ok, corrupt, dropped, wrong_format");
}

int FrameSet::NumUsableFrames() const {
  int n = 0;
  for (const Frame& f : frames) n += f.status == FrameStatus::kOk ? 1 : 0;
  return n;
}

}  // namespace px

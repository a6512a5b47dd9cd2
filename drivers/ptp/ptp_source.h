// A tethered still camera over PTP as a FrameSource ("ptp"): the hand-held mode, where one
// frame set is `shots` separate captures (2..15) that together make one light field. Each
// capture is InitiateCapture -> ObjectAdded (-> CaptureComplete) -> GetObjectInfo -> GetObject
// (-> DeleteObject), and its JPEG is decoded with OpenCV into RGB888 or BGR888.
//
// The camera's poses are unknown (no rig calibration): Describe() has no rig. The native size
// comes from the ImageSize property (0x5003) when the camera has it, else 0x0 (any size).
// A camera unplugged mid-capture: the shots already taken come back as usable frames, the
// missing ones are kDropped with an UNAVAILABLE detail naming the device, and the following
// Next() fails UNAVAILABLE until Configure reconnects. With no shot taken, Next() fails at once.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "drivers/ptp/ptp_session.h"
#include "drivers/ptp/ptp_transport.h"
#include "drivers/source/clock.h"
#include "drivers/source/frame_source.h"

namespace px {

inline constexpr int kPtpMinShots = 2;
inline constexpr int kPtpMaxShots = 15;

struct PtpSourceOptions {
  // Opens the camera (a fresh transport each time Configure connects after Stop or a loss).
  std::function<StatusOr<std::unique_ptr<ptp::PtpTransport>>()> open_transport;
  std::string label = "camera";                   // names the camera before it is connected
  std::chrono::milliseconds shot_timeout{10000};  // InitiateCapture to ObjectAdded, (0, 600000]
  ptp::SessionOptions session;
  bool delete_after_download = true;  // DeleteObject after GetObject, so the card does not fill
  Clock* clock = nullptr;             // frame timestamps; nullptr = a SteadyClock

  Status Validate() const;
};

StatusOr<std::unique_ptr<FrameSource>> MakePtpSource(PtpSourceOptions options);

}  // namespace px

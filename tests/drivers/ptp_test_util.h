// Shared set-up for the PTP tests: a simulated camera serving hand-held shots of a small Pop9.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "drivers/ptp/ptp_source.h"
#include "tests/drivers/ptp_responder.h"

namespace px::ptp::testing {

inline constexpr int kShotWidth = 160;
inline constexpr int kShotHeight = 120;

// Options for a responder serving the 9 rendered views (fails the test if they cannot be made).
inline ResponderOptions HandHeldResponderOptions() {
  ResponderOptions options;
  auto shots = RenderHandHeldShots(kShotWidth, kShotHeight);
  EXPECT_TRUE(shots.ok()) << shots.status().ToString();
  if (shots.ok()) options.jpegs = shots->jpegs;
  options.image_width = kShotWidth;
  options.image_height = kShotHeight;
  return options;
}

// A PTP source over the responder, in process. Reconnecting fails UNAVAILABLE once unplugged.
inline PtpSourceOptions ResponderSourceOptions(std::shared_ptr<PtpResponder> responder, Clock* clock = nullptr) {
  PtpSourceOptions options;
  options.label = "sim-ptp";
  options.clock = clock;
  options.shot_timeout = std::chrono::milliseconds(5000);
  options.session.busy_backoff = std::chrono::milliseconds(5);
  options.open_transport = [responder]() -> StatusOr<std::unique_ptr<PtpTransport>> {
    if (responder->unplugged()) return UnavailableError(responder->DeviceName() + ": not connected");
    return MakeResponderTransport(responder);
  };
  return options;
}

}  // namespace px::ptp::testing

// A test-only hook for crash tests: with PARALLAXD_TEST_PAUSE_AT=<phase> in its environment, the
// daemon logs "paused at <phase>" when it reaches that phase and then sleeps until it is killed,
// so a test can SIGKILL the real process at an exact point of a job. Without the variable this is
// one cached getenv and nothing else. Phases, in a job's order (README "Crash tests"):
//   capture          the frame set is in memory, nothing written yet
//   writing_capture  the frame files are written, manifest.json's temporary is complete, not renamed
//   saved            the recording is complete and journaled as saved, processing not started
//   depth, render    inside the pipeline (render: after the first clip frame reached the encoder)
//   encode           the clip's temporary file is complete and fsynced, just before its rename
//   clip_written     the clip and its report are in place, the journal not yet updated to done
#pragma once

#include <string_view>

namespace px::device {

inline constexpr const char* kTestPauseEnv = "PARALLAXD_TEST_PAUSE_AT";

void PauseHereIfAsked(std::string_view phase);

}  // namespace px::device

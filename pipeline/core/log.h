// Logging facade over spdlog: one named logger per module ("depth", "device", ...), levels set
// per module at run time with SetLogLevels("depth=debug,device=info"). error: the user lost
// something; warn: degraded result; info: one line per stage with its duration; debug: per frame.
#pragma once

#include <spdlog/spdlog.h>

#include <memory>
#include <string>
#include <string_view>

#include "pipeline/core/status.h"

namespace px {

// Returns the logger for `module`, creating it (stderr, shared format) on first use.
std::shared_ptr<spdlog::logger> Logger(const std::string& module);

// "info" sets every module; "depth=debug,device=warn" sets some. Unknown level names fail.
Status SetLogLevels(std::string_view spec);

// Names the process in every line ("[worker 000007 depth] ..."), for a child whose stderr is its
// parent's; "" = none.
void SetLogProcessName(std::string_view name);

}  // namespace px

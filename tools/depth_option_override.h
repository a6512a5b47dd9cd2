// `--option name=value` for the commands that run the depth stage (eval depth, bench): sets one
// numeric field of DepthOptions, named as in pipeline/depth/depth_options.h.
#pragma once

#include <string>

#include "pipeline/core/status.h"
#include "pipeline/depth/depth_options.h"

namespace px::cli {

// InvalidArgument naming the text when it is not name=value, the value is not a number, or no
// such option exists. The caller's options Validate() checks the range.
Status ApplyDepthOptionOverride(const std::string& text, DepthOptions* options);

}  // namespace px::cli

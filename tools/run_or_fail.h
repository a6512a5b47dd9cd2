// The callback every `parallax` subcommand uses: run it, and on failure log why and exit with 1.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <utility>

#include "pipeline/core/log.h"
#include "pipeline/core/status.h"

namespace px::cli {

// `run` returns a Status; a failure is logged under `logger` and ends the command with exit status 1.
template <typename Run>
std::function<void()> RunOrFail(std::string logger, Run run) {
  return [logger = std::move(logger), run = std::move(run)]() {
    const Status status = run();
    if (!status.ok()) {
      Logger(logger)->error("{}", status.ToString());
      throw CLI::RuntimeError(1);
    }
  };
}

}  // namespace px::cli

// `parallax eval calib`: calibration figures (rotation, centre and focal errors, reprojection
// RMS, views registered, time) on simulated rigs with perturbed lenses and the calibration
// data sets in ../shared/data, or on any folder given with --data.
#pragma once

#include <CLI/CLI.hpp>

namespace px::cli {

void AddEvalCalibCommand(CLI::App& eval);

}  // namespace px::cli

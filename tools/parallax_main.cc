// `parallax`: the offline tools: simulate a capture, make a clip (or a batch of clips), benchmark.
#include <CLI/CLI.hpp>

#include "pipeline/core/log.h"
#include "tools/batch_command.h"
#include "tools/bench_command.h"
#include "tools/calibrate_command.h"
#include "tools/clip_command.h"
#include "tools/eval_command.h"
#include "tools/import_command.h"
#include "tools/sim_command.h"

int main(int argc, char** argv) {
  CLI::App app{"parallax: multi-lens capture to 3D pan & scan clip (offline tools)"};
  app.require_subcommand(1);
  std::string log_levels = "info";
  app.add_option("--log", log_levels, "Log levels: 'info', or per module 'info,depth=debug'")->capture_default_str();
  app.parse_complete_callback([&]() {
    px::Status status = px::SetLogLevels(log_levels);
    if (!status.ok()) throw CLI::ValidationError("--log", status.message());
  });
  px::cli::AddSimCommand(app);
  px::cli::AddImportCommand(app);
  px::cli::AddClipCommand(app);
  px::cli::AddBatchCommands(app);
  px::cli::AddBenchCommand(app);
  px::cli::AddEvalCommand(app);
  px::cli::AddCalibrateCommand(app);
  CLI11_PARSE(app, argc, argv);
  return 0;
}

#include "tools/eval_command.h"

#include "tools/eval_calib_command.h"
#include "tools/eval_depth_command.h"
#include "tools/eval_faces_command.h"
#include "tools/eval_real_command.h"
#include "tools/eval_render_command.h"

namespace px::cli {

void AddEvalCommand(CLI::App& app) {
  CLI::App* eval = app.add_subcommand(
      "eval",
      "Evaluate a stage against ground truth (depth, calib, render, faces) or the product on real captures (real)");
  eval->require_subcommand(1);
  // Each tool adds its subcommand to `eval` here, one line each (e.g. AddEvalDepthCommand(*eval)).
  AddEvalRenderCommand(*eval);
  AddEvalDepthCommand(*eval);
  AddEvalCalibCommand(*eval);
  AddEvalFacesCommand(*eval);
  AddEvalRealCommand(*eval);
}

}  // namespace px::cli

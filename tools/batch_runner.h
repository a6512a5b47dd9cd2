// Many clips with the same options, one `parallax clip` child process per input (so a bad input,
// even one that crashes the pipeline, costs only its own clip), `jobs` of them at a time.
// Resumable: an input whose clip was finished with the same options and the same input is
// skipped, so a batch stopped half way (Ctrl-C, a killed job, a reboot) is simply run again.
//
// Under the output folder:
//   <name>.mp4 (.gif, .webp, or the folder <name>/ of PNG frames) with its .json, .shot.json,
//     .poster.jpg and .preview.webp, as `parallax clip` writes them;
//   batch/<name>.log        what that clip's process logged;
//   batch/<name>.done.json  written once the clip is in place: the input, the fingerprint of
//                           the input and the options, the time it took;
//   batch.json              the summary (BatchSummaryToJson), rewritten after every input
//                           (or the path given as summary_path).
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace px::cli {

struct BatchInput {
  std::filesystem::path path;  // a recording, a photo folder, a lattice photo, an MPO, an animation
  std::string name;            // the clip's name in the output folder (unique in the batch)
};

// Inputs named after their file or folder (letters, digits, '-' and '_' kept, anything else
// '_'), with "-2", "-3" ... where two would share a name: the same list names them the same way
// every time, which is what lets a batch resume.
std::vector<BatchInput> NameBatchInputs(const std::vector<std::filesystem::path>& paths);

struct BatchOptions {
  std::filesystem::path output_dir;
  int jobs = 1;                         // clips made at once
  std::filesystem::path parallax;       // the executable run as `parallax clip` for each input
  std::vector<std::string> clip_flags;  // given to every `parallax clip` (the format among them)
  std::string clip_extension = ".mp4";  // ".mp4", ".gif", ".webp", or "" for a folder of PNGs
  // What "the same options" means: a text that changes whenever the clips would (the flags that
  // shape a clip, an authored shot's contents); the input's own identity is added per input.
  std::string options_fingerprint;
  std::filesystem::path summary_path;  // empty: <output_dir>/batch.json
  bool quiet = false;                  // no line per input on stderr
  std::filesystem::path SummaryPath() const;
};

struct BatchEntry {
  std::string input;
  std::string name;
  std::string status;  // "done", "skipped" (done before with the same options), "failed", "interrupted"
  std::string clip;    // the clip's path (done, skipped)
  std::string kind;    // the camera path's kind and move (done, skipped): "novel_view", "establishing_dolly"
  std::string move;
  double seconds = 0;  // wall clock of the clip's process (skipped: of the run that made it)
  std::vector<std::string> warnings;
  std::string error;  // failed: the clip process's last error, or how it died
  std::string log;    // the clip process's log
};

struct BatchSummary {
  std::vector<BatchEntry> entries;  // in input order
  bool interrupted = false;         // SIGINT or SIGTERM stopped the batch
  double seconds = 0;
  int Count(const std::string& status) const;
};

// Runs the batch; a failing input is an entry, not an error. Errors: the output folder cannot be
// made or written, or a child process cannot be started. SIGINT and SIGTERM stop the children
// and end the batch with `interrupted` (clips finished so far are kept and count as done).
StatusOr<BatchSummary> RunBatch(const std::vector<BatchInput>& inputs, const BatchOptions& options);

nlohmann::json BatchSummaryToJson(const BatchSummary& summary, const BatchOptions& options);

// The text that identifies an input's contents for resuming: a recording by its manifest (which
// holds every frame's checksum), a photo folder by its files' names, sizes and times, a file by
// its size and time; with its absolute path.
std::string InputIdentity(const std::filesystem::path& input);

}  // namespace px::cli

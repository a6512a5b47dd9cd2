#include "tools/batch_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "capture/sha256.h"
#include "device/storage/storage_layout.h"
#include "pipeline/core/log.h"
#include "pipeline/io/durable_file.h"
#include "tools/batch_runner.h"
#include "tools/clip_flags.h"
#include "tools/run_or_fail.h"

namespace px::cli {
namespace {

namespace fs = std::filesystem;

struct BatchArgs {
  std::vector<std::string> inputs;  // batch: the inputs; rerender: the store
  std::string output;
  std::string summary;  // "" = <output>/batch.json
  int jobs = 1;
  ClipFlags flags;
  std::vector<CLI::Option*> clip_options;  // the flags above, to pass on those a user gave
  bool quiet = false;
};

// The clip flags a user gave, as `parallax clip` takes them; --format resolved (auto: mp4).
std::vector<std::string> GivenClipFlags(const BatchArgs& args, clip::ClipFormat format) {
  std::vector<std::string> flags;
  for (const CLI::Option* option : args.clip_options) {
    if (option->count() == 0 || option->get_name() == "--format") continue;
    flags.push_back(option->get_name());
    if (option->get_expected_max() == 0) continue;  // a flag: its name says it
    for (const std::string& value : option->results()) flags.push_back(value);
  }
  flags.push_back("--format");
  flags.push_back(std::string(clip::ClipFormatName(format)));
  return flags;
}

// Everything that changes the clips: the flags but --threads, and an authored shot's contents
// (the same path may hold another shot next time).
StatusOr<std::string> OptionsFingerprint(const BatchArgs& args, const std::vector<std::string>& flags) {
  std::string text;
  for (size_t i = 0; i < flags.size(); ++i) {
    if (flags[i] == "--threads") {
      ++i;
      continue;
    }
    text += flags[i] + "\n";
  }
  if (!args.flags.shot.empty()) {
    PX_ASSIGN_OR_RETURN(std::string shot, ReadFileToString(args.flags.shot));
    text += "shot " + capture::Sha256HexOfText(shot) + "\n";
  }
  return text;
}

StatusOr<BatchOptions> MakeBatchOptions(const BatchArgs& args) {
  // auto: one container for every input, mp4 (a batch names no output file to take it from).
  PX_ASSIGN_OR_RETURN(const clip::ClipFormat format,
                      clip::ParseClipFormat(args.flags.format == "auto" ? "mp4" : args.flags.format));
  // Bad flags fail here, once, not in every input's process.
  PX_RETURN_IF_ERROR(ClipJobOptionsFromFlags(args.flags, format).status());
  BatchOptions options;
  options.output_dir = fs::absolute(args.output);
  options.jobs = args.jobs;
  if (!args.summary.empty()) options.summary_path = fs::absolute(args.summary);
  std::error_code ec;
  options.parallax = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return InternalError("cannot find this executable (/proc/self/exe): " + ec.message());
  options.clip_flags = GivenClipFlags(args, format);
  PX_ASSIGN_OR_RETURN(options.options_fingerprint, OptionsFingerprint(args, options.clip_flags));
  if (args.flags.threads == 0 && args.jobs > 1) {
    // The cores shared between the clips made at once.
    const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    options.clip_flags.push_back("--threads");
    options.clip_flags.push_back(std::to_string(std::max(1, cores / args.jobs)));
  }
  options.clip_extension = format == clip::ClipFormat::kPng ? "" : std::string(clip::ClipFormatExtension(format));
  options.quiet = args.quiet;
  return options;
}

Status RunAndReport(const std::vector<BatchInput>& inputs, const BatchArgs& args) {
  PX_ASSIGN_OR_RETURN(BatchOptions options, MakeBatchOptions(args));
  auto log = Logger("batch");
  log->info("{} input(s) into {}, {} at a time", inputs.size(), options.output_dir.string(), options.jobs);
  PX_ASSIGN_OR_RETURN(BatchSummary summary, RunBatch(inputs, options));
  const fs::path summary_path = options.SummaryPath();
  log->info("{} done, {} skipped (done before), {} failed{} in {:.1f} s; summary {}",
            summary.Count("done"),
            summary.Count("skipped"),
            summary.Count("failed"),
            summary.interrupted ? ", interrupted" : "",
            summary.seconds,
            summary_path.string());
  std::printf("%s\n", summary_path.c_str());
  if (summary.interrupted) {
    return CancelledError("interrupted: " + std::to_string(summary.Count("interrupted")) +
                          " clip(s) stopped; run the same command again to finish (finished clips are kept)");
  }
  if (summary.Count("failed") > 0) {
    return AbortedError(std::to_string(summary.Count("failed")) + " of " + std::to_string(inputs.size()) +
                        " input(s) failed; each is named with its error in " + summary_path.string());
  }
  return OkStatus();
}

Status RunBatchCommand(const BatchArgs& args) {
  std::vector<fs::path> paths(args.inputs.begin(), args.inputs.end());
  return RunAndReport(NameBatchInputs(paths), args);
}

// The store's raw captures (recordings, named by job id), oldest id first; the store itself is
// only read.
Status RunRerenderCommand(const BatchArgs& args) {
  const device::StorageLayout store(args.inputs.at(0));
  std::error_code ec;
  if (!fs::is_directory(store.CapturesDir(), ec)) {
    return NotFoundError(store.root().string() + ": not a parallaxd store (no captures/ folder)");
  }
  const fs::path output = fs::weakly_canonical(fs::absolute(args.output), ec);
  const fs::path root = fs::weakly_canonical(store.root(), ec);
  const auto [mismatch, _] = std::mismatch(root.begin(), root.end(), output.begin(), output.end());
  if (mismatch == root.end()) {
    return InvalidArgumentError("-o " + args.output + " is inside the store " + root.string() +
                                ": rerendered clips go to a folder of their own, the daemon's store is only read");
  }
  std::vector<fs::path> captures;
  for (const fs::directory_entry& entry : fs::directory_iterator(store.CapturesDir(), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.' || !fs::exists(entry.path() / "manifest.json", ec)) continue;
    captures.push_back(entry.path());
  }
  if (ec) return UnavailableError("cannot list " + store.CapturesDir().string() + ": " + ec.message());
  std::sort(captures.begin(), captures.end());
  if (captures.empty()) return NotFoundError(store.CapturesDir().string() + ": no raw captures to render");
  std::vector<BatchInput> inputs;
  for (const fs::path& capture : captures) inputs.push_back({capture, capture.filename().string()});
  return RunAndReport(inputs, args);
}

void AddBatchFlags(CLI::App& command, BatchArgs& args) {
  command
      .add_option("-o,--output",
                  args.output,
                  "Folder for the clips (each named after its input, with its JSON, poster and preview), "
                  "batch/ (a log per clip) and batch.json (the summary)")
      ->required();
  command.add_option("--summary",
                     args.summary,
                     "Where the summary goes (default: batch.json in the output folder); the tasks of an array job "
                     "sharing one output folder each name their own");
  command.add_option("-j,--jobs", args.jobs, "Clips made at once (each in its own process; the cores are shared)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  args.clip_options = AddClipFlags(command, args.flags);
  command.add_flag("-q,--quiet", args.quiet, "No line per input");
}

}  // namespace

void AddBatchCommands(CLI::App& app) {
  auto batch_args = std::make_shared<BatchArgs>();
  CLI::App* batch = app.add_subcommand(
      "batch",
      "A clip of every input with the same clip flags (recordings, photo folders, lattice photos, MPO files, "
      "animations); run again, it skips the clips already made from the same input with the same flags");
  batch->add_option("inputs", batch_args->inputs, "Inputs, as `parallax clip` takes them")
      ->required()
      ->check(CLI::ExistingPath);
  AddBatchFlags(*batch, *batch_args);
  batch->callback(RunOrFail("batch", [batch_args] { return RunBatchCommand(*batch_args); }));

  auto rerender_args = std::make_shared<BatchArgs>();
  CLI::App* rerender = app.add_subcommand(
      "rerender",
      "A clip of every raw capture in a parallaxd store (its storage.root) with new clip flags, into a folder of "
      "its own; the store is only read, so every raw capture and clip there stays; resumable like batch");
  rerender->add_option("store", rerender_args->inputs, "The daemon's store (storage.root)")
      ->required()
      ->expected(1)
      ->check(CLI::ExistingDirectory);
  AddBatchFlags(*rerender, *rerender_args);
  rerender->callback(RunOrFail("rerender", [rerender_args] { return RunRerenderCommand(*rerender_args); }));
}

}  // namespace px::cli

#!/bin/bash
# The container's entry script as a batch engine runs it, without a cluster: three inputs in a
# folder, tasks started with Kubernetes' and Slurm's index variables, each makes its own input's
# clip (and only that one) with the flags from PARALLAX_FLAGS; a retried task makes nothing again;
# an index past the inputs and a missing index are refused by name. The manifest and the Dockerfile
# are checked to name the entry point and the index mode that the script expects.
# Usage: parallax_job_test.sh PATH/TO/parallax
set -euo pipefail
parallax=$(realpath "$1")
here=$(cd "$(dirname "$0")" && pwd)
job=$here/parallax-job
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v jq >/dev/null || { echo "SKIP: jq is not installed (scripts/bootstrap --test installs it)"; exit 77; }
field() { jq -r "$2" "$1"; }

"$parallax" sim --tile 160 120 -o "$dir/rec" >/dev/null
mkdir -p "$dir/data/in"
for name in c_garden a_kitchen b_stairs; do cp -r "$dir/rec" "$dir/data/in/$name"; done
export PARALLAX="$parallax" PARALLAX_INPUT="$dir/data/in" PARALLAX_OUTPUT="$dir/data/out"
export PARALLAX_FLAGS="--duration 0.4 --fps 5 --no-faces --aspect 9:16 --height 96 -q"

# Kubernetes: index 1 is b_stairs (inputs sorted by name).
JOB_COMPLETION_INDEX=1 bash "$job" 2>"$dir/k8s.log" >/dev/null || fail "task 1 failed: $(tail -3 "$dir/k8s.log")"
[[ -s $dir/data/out/b_stairs.mp4 ]] || fail "task 1 did not make b_stairs.mp4: $(ls "$dir/data/out")"
[[ ! -e $dir/data/out/a_kitchen.mp4 && ! -e $dir/data/out/c_garden.mp4 ]] || fail "task 1 made another input's clip"
size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=s=x:p=0 "$dir/data/out/b_stairs.mp4")
[[ $size == 54x96 ]] || fail "b_stairs.mp4 is $size, want 54x96 from PARALLAX_FLAGS"
summary=$dir/data/out/batch/b_stairs.summary.json
[[ $(field "$summary" ".done") -eq 1 ]] || fail "task 1's summary: $(cat "$summary")"

# Slurm: indexes 0 and 2, and task 1 retried (skipped: made before with the same flags).
SLURM_ARRAY_TASK_ID=0 bash "$job" 2>>"$dir/slurm.log" >/dev/null || fail "task 0 failed"
SLURM_ARRAY_TASK_ID=2 bash "$job" 2>>"$dir/slurm.log" >/dev/null || fail "task 2 failed"
[[ -s $dir/data/out/a_kitchen.mp4 && -s $dir/data/out/c_garden.mp4 ]] || fail "tasks 0 and 2 made no clips"
SLURM_ARRAY_TASK_ID=1 bash "$job" 2>>"$dir/slurm.log" >/dev/null || fail "the retried task 1 failed"
[[ $(field "$summary" ".skipped") -eq 1 ]] || fail "the retried task made its clip again"

# Refusals that name the problem.
status=0; JOB_COMPLETION_INDEX=3 bash "$job" 2>"$dir/bad.log" || status=$?
[[ $status -eq 2 ]] && grep -q "holds 3 input(s)" "$dir/bad.log" || fail "index 3 of 3: $status $(cat "$dir/bad.log")"
status=0; env -u JOB_COMPLETION_INDEX -u SLURM_ARRAY_TASK_ID bash "$job" 2>"$dir/bad.log" || status=$?
[[ $status -eq 2 ]] && grep -q "no index" "$dir/bad.log" || fail "no index: $status $(cat "$dir/bad.log")"

# The recipe agrees with the script.
grep -q "completionMode: Indexed" "$here/kubernetes/indexed-job.yaml" || fail "the manifest is not an Indexed Job"
grep -q "ENTRYPOINT \[\"/usr/local/bin/parallax-job\"\]" "$here/Dockerfile" || fail "the image's entry point is not parallax-job"
grep -q "install -m 0755 deploy/parallax-job /usr/local/bin/parallax-job" "$here/Dockerfile" || fail "the image does not install parallax-job"
grep -q "FROM debian:12" "$here/Dockerfile" || fail "the image is not Debian 12"
echo "[figures] parallax-job: 3 tasks by index (Kubernetes, Slurm), a retry skipped, 2 bad indexes refused"

#!/bin/bash
# `parallax batch` over 20 recordings and one broken photo: the batch is killed (SIGKILL, with its
# clip processes) part way; run again, it redoes none of the clips that finished, makes the rest,
# and names the broken input with its error in the summary without stopping the others. Then
# `parallax rerender` over a store's captures with other flags, and SIGTERM ending a batch cleanly.
# Usage: batch_test.sh PATH/TO/parallax
set -euo pipefail
parallax=$1
dir=$(mktemp -d)
trap 'kill -9 -- -"${pgid:-999999}" 2>/dev/null || true; rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v jq >/dev/null || { echo "SKIP: jq is not installed (scripts/bootstrap --test installs it)"; exit 77; }
field() { jq -r "$2" "$1"; }

"$parallax" sim --tile 160 120 -o "$dir/rec" >/dev/null
mkdir "$dir/inputs"
for i in $(seq -w 1 20); do ln -s "$dir/rec" "$dir/inputs/shot$i"; done
head -c 3000 /dev/urandom > "$dir/inputs/broken.jpg"
flags=(--duration 0.4 --fps 5 --no-faces --size 96x128)

# First run, killed hard (its whole process group) once six clips are finished.
setsid "$parallax" batch "$dir"/inputs/* -o "$dir/out" --jobs 2 "${flags[@]}" >"$dir/first.log" 2>&1 &
pgid=$!
for _ in $(seq 600); do
  done_count=$( (find "$dir/out/batch" -name '*.done.json' 2>/dev/null || true) | wc -l)
  [[ $done_count -ge 6 ]] && break
  kill -0 "$pgid" 2>/dev/null || fail "the first batch ended before it was killed: $(tail -5 "$dir/first.log")"
  sleep 0.1
done
kill -9 -- -"$pgid"
wait "$pgid" 2>/dev/null || true
finished=$(ls "$dir/out/batch/"*.done.json | wc -l)
[[ $finished -ge 6 && $finished -lt 21 ]] || fail "$finished clips finished before the kill"
finished_files=$(cd "$dir/out" && for f in batch/*.done.json; do echo "$f $(basename "$f" .done.json).mp4"; done)
stamps() { (cd "$dir/out" && stat -c '%n %y' $finished_files); }
stamps_before=$(stamps)

# Second run: the finished ones are skipped, the rest made, the broken photo named.
status=0
"$parallax" batch "$dir"/inputs/* -o "$dir/out" --jobs 2 "${flags[@]}" >"$dir/second.log" 2>&1 || status=$?
[[ $status -eq 1 ]] || fail "the second batch exited $status, want 1 (one input failed): $(tail -5 "$dir/second.log")"
summary="$dir/out/batch.json"
[[ $(field "$summary" ".inputs") -eq 21 ]] || fail "summary lists $(field "$summary" ".inputs") inputs"
[[ $(field "$summary" ".skipped") -eq $finished ]] || fail "skipped $(field "$summary" ".skipped"), want $finished"
[[ $(field "$summary" ".done") -eq $((20 - finished)) ]] || fail "made $(field "$summary" ".done"), want $((20 - finished))"
[[ $(field "$summary" ".failed") -eq 1 ]] || fail "failed $(field "$summary" ".failed"), want 1"
[[ $(field "$summary" ".entries[0].status") == failed && $(field "$summary" ".entries[0].input") == */broken.jpg ]] ||
  fail "the broken input's entry: $(field "$summary" ".entries[0]")"
error=$(field "$summary" ".entries[0].error")
grep -qiE "broken.jpg|jpeg|image|decod" <<<"$error" || fail "the broken input's error does not say what is wrong: $error"
stamps_after=$(stamps)
[[ "$stamps_before" == "$stamps_after" ]] || fail "a finished clip was made again"
for i in $(seq -w 1 20); do
  [[ -s "$dir/out/shot$i.mp4" && -s "$dir/out/shot$i.json" && -s "$dir/out/shot$i.poster.jpg" ]] || fail "shot$i: no clip"
done
size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=s=x:p=0 "$dir/out/shot07.mp4")
[[ $size == 96x128 ]] || fail "shot07.mp4 is $size, want the asked 96x128"
mode=$(field "$summary" ".entries[7].mode.kind")
[[ -n $mode ]] || fail "no mode in the summary"

# Third run, same flags: nothing to do but the broken input.
"$parallax" batch "$dir"/inputs/shot0* -o "$dir/out" "${flags[@]}" -q >/dev/null 2>&1 || fail "a batch of finished inputs failed"
[[ $(field "$summary" ".skipped") -eq 9 && $(field "$summary" ".done") -eq 0 ]] || fail "finished inputs made again"

# Other flags make them again.
"$parallax" batch "$dir"/inputs/shot01 -o "$dir/out" --duration 0.4 --fps 4 --no-faces --size 96x128 -q >/dev/null 2>&1
[[ $(field "$summary" ".done") -eq 1 ]] || fail "a clip with other flags was skipped"

# rerender: every capture of a store, into a folder of its own; the store untouched.
mkdir -p "$dir/store/captures" "$dir/store/clips"
cp -r "$dir/rec" "$dir/store/captures/job-1"
cp -r "$dir/rec" "$dir/store/captures/job-2"
before=$(find "$dir/store" -type f -printf '%p %s %T@\n' | sort)
"$parallax" rerender "$dir/store" -o "$dir/store/clips/new" "${flags[@]}" -q >/dev/null 2>&1 &&
  fail "rerender wrote into the store"
"$parallax" rerender "$dir/store" -o "$dir/rerendered" --aspect 1:1 --height 64 --duration 0.4 --fps 5 --no-faces -q \
  >/dev/null 2>&1 || fail "rerender failed"
[[ -s "$dir/rerendered/job-1.mp4" && -s "$dir/rerendered/job-2.mp4" ]] || fail "rerender made no clip per capture"
size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=s=x:p=0 "$dir/rerendered/job-2.mp4")
[[ $size == 64x64 ]] || fail "the rerendered clip is $size, want 64x64"
after=$(find "$dir/store" -type f -printf '%p %s %T@\n' | sort)
[[ "$before" == "$after" ]] || fail "rerender changed the store"

# SIGTERM: the batch stops its clip processes, says so and exits non-zero; run again, it finishes.
"$parallax" batch "$dir"/inputs/shot1* -o "$dir/term" "${flags[@]}" >"$dir/term.log" 2>&1 &
batch_pid=$!
for _ in $(seq 600); do [[ -e "$dir/term/batch/shot10.log" ]] && break; sleep 0.1; done
kill -TERM "$batch_pid"
status=0; wait "$batch_pid" || status=$?
[[ $status -ne 0 ]] || fail "a batch stopped by SIGTERM exited 0"
[[ $(field "$dir/term/batch.json" ".interrupted") == true ]] || fail "the summary does not say interrupted"
grep -q "run the same command again" "$dir/term.log" || fail "the interrupted batch does not say how to finish"
leftovers=$(find "$dir/term" -maxdepth 1 -name '.*.tmp-*')
[[ -z $leftovers ]] || fail "the stopped clip processes left temporaries: $leftovers"
"$parallax" batch "$dir"/inputs/shot1* -o "$dir/term" "${flags[@]}" -q >/dev/null 2>&1 || fail "finishing the batch failed"
[[ $(( $(field "$dir/term/batch.json" ".done") + $(field "$dir/term/batch.json" ".skipped") )) -eq 10 ]] ||
  fail "the finished batch does not hold all 10 clips"
echo "[figures] batch: killed after $finished of 21, resumed: $finished skipped, $((20 - finished)) made, 1 failed"

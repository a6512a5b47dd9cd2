#!/bin/bash
# `parallax clip` writes the shot it used beside the clip; `parallax clip --shot` of that file
# renders the same camera path from it (paper 4.4): the shot written by the replay equals the
# first one to 1e-9 in every number, and the replay's report says the path was authored.
# Usage: clip_shot_round_trip_test.sh PATH/TO/parallax
set -euo pipefail
parallax=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$parallax" sim --tile 320 240 -o "$dir/rec" >/dev/null
"$parallax" clip "$dir/rec" -o "$dir/chosen.mp4" --duration 1 --fps 5 -q --no-faces >/dev/null
[[ -s "$dir/chosen.shot.json" ]] || fail "no shot written beside the clip"
"$parallax" clip "$dir/rec" -o "$dir/replayed.mp4" --duration 1 --fps 5 -q --no-faces \
  --shot "$dir/chosen.shot.json" >/dev/null
[[ -s "$dir/replayed.mp4" ]] || fail "the shot did not render a clip"
grep -q '"reason": "authored shot' "$dir/replayed.json" || fail "the replay's report does not name the authored shot"

# Every number of the two shots, in order, within 1e-9 (the JSON's last digits may differ).
numbers() { grep -oE -- '-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?' "$1"; }
count_a=$(numbers "$dir/chosen.shot.json" | wc -l)
count_b=$(numbers "$dir/replayed.shot.json" | wc -l)
[[ "$count_a" -gt 10 && "$count_a" -eq "$count_b" ]] || fail "the shots have $count_a and $count_b numbers"
worst=$(paste <(numbers "$dir/chosen.shot.json") <(numbers "$dir/replayed.shot.json") |
  awk '{ d = $1 - $2; if (d < 0) d = -d; if (d > w) w = d } END { printf "%.3g", w }')
awk -v w="$worst" 'BEGIN { exit !(w <= 1e-9) }' || fail "the replayed shot differs by $worst"
grep -q '"format": "parallax-shot"' "$dir/replayed.shot.json" || fail "the replayed shot has no format tag"
echo "[figures] clip --shot round trip: $count_a numbers, worst difference $worst"

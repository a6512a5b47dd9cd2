#!/bin/bash
# A PNG whose header claims 40000x40000 pixels (1.6 gigapixels in 69 bytes) is refused before any
# decoding by every command that reads photos: an exit status (not a signal), the file and its
# claimed size named, and little memory (peak RSS printed where /usr/bin/time exists).
# Usage: hostile_image_test.sh PATH/TO/parallax
set -uo pipefail
parallax=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

mkdir "$dir/photos"
for name in a b c; do printf '\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\x9c\x40\x00\x00\x9c\x40\x08\x02\x00\x00\x00\xde\x6e\x99\x52\x00\x00\x00\x0c\x49\x44\x41\x54\x78\x9c\x63\x60\xa0\x3d\x00\x00\x00\x64\x00\x01\x86\x64\x3c\x35\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82' > "$dir/photos/$name.png"; done
[[ $(stat -c %s "$dir/photos/a.png") -eq 69 ]] || fail "the crafted PNG was not written"

# Runs one command; it must fail cleanly, naming the crafted file and its claimed size.
refused() {
  local what=$1; shift
  local peak="n/a"
  if [[ -x /usr/bin/time ]]; then
    /usr/bin/time -f "%M" -o "$dir/peak" "$@" >"$dir/out" 2>&1
    local rc=$?
    peak="$(tail -1 "$dir/peak") KB"
  else
    "$@" >"$dir/out" 2>&1
    local rc=$?
  fi
  [[ $rc -ne 0 && $rc -lt 128 ]] || { cat "$dir/out" >&2; fail "$what: exit status $rc (0 or a signal)"; }
  grep -q "a.png: its header claims 40000x40000 pixels" "$dir/out" ||
    { cat "$dir/out" >&2; fail "$what: the error does not name the file and its claimed size"; }
  echo "[figures] $what: refused (exit $rc), peak RSS $peak"
}

refused "import of a photo folder" "$parallax" import "$dir/photos" -o "$dir/rec"
refused "clip of a photo folder" "$parallax" clip -q "$dir/photos" -o "$dir/clip.mp4"
refused "import of a lattice photo" "$parallax" import --lattice auto "$dir/photos/a.png" -o "$dir/rec2"
refused "calibrate" "$parallax" calibrate "$dir/photos/a.png" "$dir/photos/b.png" "$dir/photos/c.png" -o "$dir/rig.json"
[[ ! -e "$dir/rec" && ! -e "$dir/rec2" && ! -e "$dir/rig.json" && ! -e "$dir/clip.mp4" ]] || fail "a refused command left output behind"

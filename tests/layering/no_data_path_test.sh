#!/bin/bash
# No path to the project's real data (../shared beside the source) is compiled into a product
# binary: parallaxd and parallax find it at run time (PX_DATA_DIR, or beside the checkout whose
# build tree they run from; sim/synthetic/data_paths.h), so an installed binary never looks there.
# Usage: no_data_path_test.sh SOURCE_DIR BINARY...
set -euo pipefail
source_dir=$1
shift
for binary in "$@"; do
  for path in "$source_dir/../shared" "$(realpath -m "$source_dir/../shared")"; do
    if grep -qaF "$path" "$binary"; then
      echo "FAIL: $binary holds the path $path" >&2
      exit 1
    fi
  done
done
echo "[figures] no data path: $# product binaries hold no path to $source_dir/../shared"

#!/bin/bash
# Every C++ file of the project is as clang-format (.clang-format at the root) writes it; prints
# the files that are not, with the fix. Exit 77 (ctest: skipped) when clang-format is missing
# (scripts/test installs it).
# Usage: check_format.sh PROJECT_ROOT
set -euo pipefail
cd "$1"
if ! command -v clang-format >/dev/null 2>&1; then
  echo "SKIP: clang-format is not installed (scripts/bootstrap --test installs it)"
  exit 77
fi
if [[ -d .git ]] && command -v git >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -co --exclude-standard '*.cc' '*.h')
else
  mapfile -t files < <(find device drivers eval pipeline sim tests -name '*.cc' -o -name '*.h' | sort)
fi
bad=()
for file in "${files[@]}"; do
  [[ -f $file ]] || continue
  clang-format --dry-run --Werror "$file" >/dev/null 2>&1 || bad+=("$file")
done
if (( ${#bad[@]} > 0 )); then
  echo "FAIL: ${#bad[@]} of ${#files[@]} files are not formatted; fix with: clang-format -i ${bad[*]}"
  exit 1
fi
echo "[figures] format: ${#files[@]} files as clang-format $(clang-format --version | grep -oE '[0-9]+\.[0-9]+\.[0-9]+') writes them"

#!/usr/bin/env bash
# clang-format over the project's C and C++ sources (.clang-format at the top).
#   tools/format.sh          reformat in place
#   tools/format.sh --check  change nothing; list unformatted files and exit 1 if there are any
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
if ! command -v clang-format >/dev/null; then
  echo "tools/format.sh: clang-format not found (tools/setup.sh installs it)" >&2
  exit 2
fi
mapfile -t files < <(find core adapters scenes tools tests python \
  \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -type f | sort)
if [ "${1:-}" = "--check" ]; then
  bad=()
  for f in "${files[@]}"; do
    clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
  done
  if [ ${#bad[@]} -gt 0 ]; then
    echo "tools/format.sh: not clang-formatted (run tools/format.sh):" >&2
    printf '  %s\n' "${bad[@]}" >&2
    exit 1
  fi
  echo "tools/format.sh: ${#files[@]} files formatted"
else
  clang-format -i "${files[@]}"
fi

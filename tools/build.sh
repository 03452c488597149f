#!/usr/bin/env bash
# Configures and builds one build tree: tools/build.sh [BUILD_DIR] [extra cmake args...]
# Default: build/ in Release. Reuses an existing tree.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$repo/build}
shift || true
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" > /dev/null
cmake --build "$build" -j "$jobs"

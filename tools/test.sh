#!/usr/bin/env bash
# The whole test suite: set-up, the format check (tools/format.sh --check), a Release build with
# every test (ctest), the Python package pip-installed into a new venv and its tests, the fuzz
# targets for 20 s each (tools/fuzz.sh: libFuzzer, its own clang build tree of the core and scene
# libraries only), then the same tests under AddressSanitizer + UndefinedBehaviorSanitizer.
# Exit status is non-zero on any failure.
#   tools/test.sh            everything
#   tools/test.sh --fast     the Release build only (no sanitizer build)
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=$(nproc 2>/dev/null || echo 2)
"$repo/tools/setup.sh"

echo "== Format check"
"$repo/tools/format.sh" --check

echo "== Release build and tests"
# MLCP_BULLET_FLOAT_CHECK: the Bullet adapter compiled against single-precision Bullet too.
"$repo/tools/build.sh" "$repo/build" -DMLCP_BULLET_FLOAT_CHECK=ON
ctest --test-dir "$repo/build" --output-on-failure -j "$jobs"

echo "== pip install . into a new venv, and python/tests on the installed package"
# A fresh build of its own (scikit-build-core, pyproject.toml): 6.7 min on 2 shared cores.
pyvenv=$(mktemp -d)
/usr/bin/python3 -m venv "$pyvenv"
"$pyvenv/bin/pip" install -q --disable-pip-version-check -r "$repo/tools/requirements.txt"
CMAKE_BUILD_PARALLEL_LEVEL=$jobs "$pyvenv/bin/pip" install -q --disable-pip-version-check "$repo"
(cd "$repo" && PYTHONDONTWRITEBYTECODE=1 "$pyvenv/bin/python" -m pytest -q -p no:cacheprovider \
  python/tests)
rm -rf "$pyvenv"

if [ "${1:-}" != "--fast" ]; then
  echo "== Fuzzing (20 s per target)"
  "$repo/tools/fuzz.sh" 20

  echo "== Sanitizer build (ASan + UBSan) and tests"
  "$repo/tools/build.sh" "$repo/build-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMLCP_SANITIZE=ON
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$repo/build-asan" --output-on-failure -j "$jobs"
fi
echo "tools/test.sh: all tests passed"

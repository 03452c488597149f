#!/usr/bin/env bash
# Installs the build tree into a temporary prefix, then, as a user would:
#  1. configures, builds and runs the consumer project with find_package(mlcp CONFIG
#     COMPONENTS core bullet ode) (C++ and C programs; see CMakeLists.txt);
#  2. builds the C program again with pkg-config alone (mlcp-ode.pc) and runs it;
#  3. imports the installed Python package (when the build has one) and solves with it;
#  4. checks that asking for a component the installation lacks fails at configure time,
#     naming it, and that a newer version than installed is refused.
set -euo pipefail
build_dir=$1 source_dir=$2 generator=${3:-Ninja}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cmake --install "$build_dir" --prefix "$prefix" > /dev/null
! find "$prefix/include" -name 'objects.h' -o -name 'joint.h' | grep -q . ||
  { echo "ODE's internal headers were installed"; exit 1; }

cmake -S "$source_dir" -B "$work/build" -G "$generator" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release > "$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/build/consumer"
"$work/build/consumer_c"

pc_dir=$(dirname "$(find "$prefix" -name mlcp-ode.pc)")
export PKG_CONFIG_PATH=$pc_dir
# shellcheck disable=SC2046
cc -std=c99 -o "$work/consumer_pc" "$source_dir/main.c" "$source_dir/ode_drop.c" \
  $(pkg-config --cflags --libs mlcp-ode)
"$work/consumer_pc" | sed 's/^c:/pkg-config c:/'

site=$(find "$prefix" -path '*site-packages/mlcp' -type d | head -1)
if [ -n "$site" ]; then
  python=$(cd "$source_dir/../.." && pwd)/.venv/bin/python
  (cd "$work" && PYTHONPATH=$(dirname "$site") "$python" -c '
import mlcp
r = mlcp.solve([[2.0, 1.0], [1.0, 2.0]], [-1.0, -1.0], solver="lemke")
assert r.converged and abs(r.x[0] - 1 / 3) < 1e-12, r
assert mlcp.__file__.startswith("'"$prefix"'"), mlcp.__file__
print("python: installed mlcp solves,", r.status)')
fi

# A component that is not there, and a version that is not there.
mkdir -p "$work/probe"
cat > "$work/probe/CMakeLists.txt" <<'PROBE'
cmake_minimum_required(VERSION 3.20)
project(probe LANGUAGES CXX)
find_package(mlcp ${WANT_VERSION} CONFIG REQUIRED COMPONENTS ${WANT})
PROBE
expect_failure() {  # expect_failure WHAT-IN-OUTPUT cmake-args...
  local want=$1
  shift
  if cmake -S "$work/probe" -B "$work/probe/build-$RANDOM" -DCMAKE_PREFIX_PATH="$prefix" "$@" \
    > "$work/probe.log" 2>&1; then
    echo "configure with $* did not fail"
    exit 1
  fi
  grep -q "$want" "$work/probe.log" || { cat "$work/probe.log"; echo "no '$want' in the error"; exit 1; }
}
expect_failure "component 'physx' is not in this installation" -DWANT=physx -DWANT_VERSION=0.1
expect_failure 'requested version "99"' -DWANT=core -DWANT_VERSION=99
echo "find_package refuses a missing component and a newer version"

#!/usr/bin/env bash
# Installs everything mlcp needs on Debian 12 (run as root, or with sudo available; clang and
# libclang-rt-14-dev, which holds libFuzzer, are for tools/fuzz.sh) and fetches ODE's internal
# headers from Debian's source package. Idempotent and quick when everything is already there.
# Used by tools/test.sh and tools/main.sh.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libsuitesparse-dev
  libbullet-dev libode-dev
  libgtest-dev libbenchmark-dev nlohmann-json3-dev libcli11-dev
  clang-format dpkg-dev python3 python3-venv
  clang libclang-rt-14-dev
)

sudo_if_needed() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

# Python's headers, for the bindings (python/, built with nanobind from the venv below).
packages+=(python3-dev)

# Optional, for the peer benchmark only (tests/bench/siconos_bench: Siconos numerics' solvers on
# our captured islands); the build finds it or leaves that benchmark out. On Debian 12 it brings
# 20 packages (HDF5, MUMPS, OpenBLAS, ...) and installed in 7.5 s here.
packages+=(libsiconos-numerics-dev)

# Whether OpenBLAS was on the machine before this set-up (see the alternatives below).
had_openblas=0
dpkg-query -W -f='${Status}' libopenblas0-pthread 2>/dev/null | grep -q "install ok installed" &&
  had_openblas=1

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# ODE's internal headers come from the Debian source package `ode`: apt needs a deb-src entry.
src_list=/etc/apt/sources.list.d/mlcp-deb-src.sources
need_update=0
if [ ! -f "$src_list" ]; then
  echo "setup: adding a deb-src entry for Debian bookworm ($src_list)"
  sudo_if_needed tee "$src_list" > /dev/null <<'SRC'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  need_update=1
fi

if [ ${#missing[@]} -gt 0 ] || [ $need_update -eq 1 ]; then
  echo "setup: installing ${missing[*]:-(sources only)}"
  sudo_if_needed apt-get update -qq
  [ ${#missing[@]} -eq 0 ] || DEBIAN_FRONTEND=noninteractive sudo_if_needed apt-get install -y -qq --no-install-recommends "${missing[@]}" > /dev/null
fi

# Siconos pulls in OpenBLAS, whose libblas.so.3 / liblapack.so.3 outrank the reference ones in
# Debian's alternatives: that would change, for every program, the BLAS that SuiteSparse and
# LAPACK users load, and start its threads. When this set-up is what brought OpenBLAS, the reference libraries
# stay the system's (as without Siconos; Siconos links OpenBLAS directly); a machine that had
# OpenBLAS before keeps its owner's choice.
if [ $had_openblas -eq 0 ]; then
  multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || gcc -dumpmachine)
  for pair in "libblas.so.3 blas" "liblapack.so.3 lapack"; do
    read -r lib dir <<< "$pair"
    ref=/usr/lib/$multiarch/$dir/$lib
    alt=$lib-$multiarch
    if [ -e "$ref" ] && [ "$(readlink "/etc/alternatives/$alt" 2>/dev/null)" != "$ref" ]; then
      echo "setup: keeping the reference $lib as the system's (not OpenBLAS's)"
      sudo_if_needed update-alternatives --set "$alt" "$ref" > /dev/null
    fi
  done
fi

if [ -x "$repo/tools/fetch-ode-source.sh" ]; then
  "$repo/tools/fetch-ode-source.sh"
fi

# Python tools (charts) run from a venv built from tools/requirements.txt.
if [ -f "$repo/tools/requirements.txt" ]; then
  venv="$repo/.venv"
  stamp="$venv/.requirements"
  if [ ! -f "$stamp" ] || ! cmp -s "$repo/tools/requirements.txt" "$stamp"; then
    echo "setup: building the Python venv in $venv"
    /usr/bin/python3 -m venv "$venv"
    "$venv/bin/pip" install -q --disable-pip-version-check -r "$repo/tools/requirements.txt"
    cp "$repo/tools/requirements.txt" "$stamp"
  fi
fi
# The Python package mlcp (python/) is built into build/python by tools/build.sh; the venv finds
# it there through a .pth file (another build tree: PYTHONPATH=<build>/python).
if [ -x "$repo/.venv/bin/python" ]; then
  site=$("$repo/.venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
  pth="$site/mlcp-build.pth"
  [ "$(cat "$pth" 2>/dev/null)" = "$repo/build/python" ] || echo "$repo/build/python" > "$pth"
fi
echo "setup: ok"

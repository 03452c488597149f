#!/usr/bin/env bash
# Puts ODE 0.16.2's source tree (for its INTERNAL headers, ode/src/*.h) at
#   ${MLCP_DEPS_DIR:-<repo>/.deps}/ode-0.16.2
# from Debian's source package `ode`, the same version as the installed libode-dev. Nothing of
# it is committed (.deps/ is ignored). Idempotent: does nothing when the tree is already there.
#
# Needs a deb-src entry for bookworm (tools/setup.sh writes one) and `apt-get update` after it.
# The orig tarball is downloaded with `apt-get source --download-only ode` (no dpkg-source
# unpacking, no build dependencies) and unpacked with tar.
set -euo pipefail

version=0.16.2
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
deps=${MLCP_DEPS_DIR:-$repo/.deps}
dest=$deps/ode-$version

die() {
  echo "fetch-ode-source: $*" >&2
  exit 1
}

# The headers the adapter includes; their presence marks a complete tree.
is_complete() {
  [ -f "$1/ode/src/objects.h" ] && [ -f "$1/ode/src/joints/joint.h" ] &&
    [ -f "$1/ode/src/step.h" ] && [ -f "$1/ode/src/lcp.h" ] && [ -f "$1/ode/src/util.h" ]
}

# The version the tree says it is (configure.ac: AC_INIT([ODE],[0.16.2],...)).
tree_version() {
  sed -n 's/^AC_INIT(\[ODE\],\[\([^]]*\)\].*/\1/p' "$1/configure.ac" 2>/dev/null | head -n1
}

if is_complete "$dest" && [ "$(tree_version "$dest")" = "$version" ]; then
  echo "fetch-ode-source: ODE $version source already at $dest"
  exit 0
fi

command -v apt-get > /dev/null || die "apt-get not found: this script needs Debian's apt to fetch the source package 'ode' $version"
command -v tar > /dev/null || die "tar not found"

mkdir -p "$deps"
work=$(mktemp -d "$deps/.ode-fetch.XXXXXX")
trap 'rm -rf "$work"' EXIT

echo "fetch-ode-source: apt-get source --download-only ode (into $work)"
if ! (cd "$work" && apt-get source --download-only -qq ode > "$work/apt.log" 2>&1); then
  cat "$work/apt.log" >&2
  die "'apt-get source --download-only ode' failed. It needs a deb-src line for Debian bookworm
  (e.g. /etc/apt/sources.list.d/mlcp-deb-src.sources with 'Types: deb-src', 'URIs:
  http://deb.debian.org/debian', 'Suites: bookworm', 'Components: main', written by tools/setup.sh)
  followed by 'apt-get update'. Alternatively unpack ode_$version.orig.tar.gz yourself into $dest"
fi

orig=$(ls "$work"/ode_"$version".orig.tar.* 2> /dev/null | head -n1 || true)
[ -n "$orig" ] || die "apt-get source did not download ode_$version.orig.tar.*; the archive may carry another ODE version (see $work/apt.log)"

mkdir -p "$work/x"
tar -xf "$orig" -C "$work/x"
top=$(find "$work/x" -mindepth 1 -maxdepth 1 -type d | head -n1)
[ -n "$top" ] && is_complete "$top" || die "the tarball $orig lacks ode/src/{objects,step,lcp,util}.h or joints/joint.h"
got=$(tree_version "$top")
[ "$got" = "$version" ] || die "the source package is ODE '$got', expected $version (the installed libode-dev must match the internal headers)"

rm -rf "$dest"
mv "$top" "$dest"
echo "fetch-ode-source: ODE $version source unpacked at $dest"

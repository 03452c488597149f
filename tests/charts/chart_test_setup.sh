# Sourced by the chart tests (REPO OUTDIR as $1 $2): sets repo, out and py (the venv's Python),
# skips the test (exit 77) when the venv is missing, empties OUTDIR, and defines fail.
repo=$1
out=$2
py="$repo/.venv/bin/python"
if [ ! -x "$py" ]; then
  echo "SKIP: $py is missing; run tools/setup.sh to build the chart venv"
  exit 77
fi
rm -rf "$out"
mkdir -p "$out"
fail() { echo "FAIL: $*"; exit 1; }

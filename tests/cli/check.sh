# Sourced by the command-line tests: check NAME EXPECTED_CODE PATTERN -- command...
# runs the command, counts it passed when the exit code and a line of the output match.
passed=0 failed=0
check() {
  local name=$1 want=$2 pattern=$3
  shift 4
  local out code
  out=$("$@" 2>&1)
  code=$?
  if [ "$code" -eq "$want" ] && grep -qE -- "$pattern" <<< "$out"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $name: exit $code (want $want), output lacks /$pattern/:"
    sed 's/^/    /' <<< "$out" | head -20
  fi
}

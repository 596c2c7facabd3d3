# The pass/fail bookkeeping the tool-level tests share (sourced, not run: ctest runs tests/cli/*.sh only). The
# sourcing script sets T, its scratch folder, and reports "$passes passed, $fails failed" at the end; with
# CHECK_TIMEOUT set, each checked command is ended after that many seconds (timeout's exit 124 then fails it).
fails=0
passes=0
check() {  # check NAME EXPECTED_CODE COMMAND...
  local name=$1 expected=$2
  shift 2
  ${CHECK_TIMEOUT:+timeout "$CHECK_TIMEOUT"} "$@" >"$T/out" 2>"$T/err"
  local code=$?
  if [ "$code" != "$expected" ]; then
    echo "FAIL $name: exit $code, expected $expected"; cat "$T/err"; fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}
expect_err() {  # expect_err NAME PATTERN: stderr has exactly one line and it matches
  if [ "$(wc -l <"$T/err")" != 1 ] || ! grep -q -- "$2" "$T/err"; then
    echo "FAIL $1: stderr should be one line matching '$2':"; cat "$T/err"; fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}

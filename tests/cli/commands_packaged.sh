#!/usr/bin/env bash
# Every external command the tests and scripts run comes from a package scripts/install-deps.sh names (issue 45: the
# test command failed on a bare Debian 12 for want of `file`, which the developer's machine had). Then the same
# check with `file` dropped from the list must fail and name it: the check can fail.
# Usage: commands_packaged.sh BUILD_DIR SOURCE_DIR
set -u
src=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
source "$src/tests/cli/lib/check.sh"
check "every command covered" 0 /usr/bin/python3 "$src/scripts/check-commands.py"
check "without file, it fails" 1 /usr/bin/python3 "$src/scripts/check-commands.py" --without file
if grep -q "^check-commands: file: /usr/bin/file comes from file" "$T/err"; then
  passes=$((passes + 1))
else
  echo "FAIL the report names file:"; cat "$T/err"; fails=$((fails + 1))
fi
echo "$passes passed, $fails failed"
[ "$fails" = 0 ]

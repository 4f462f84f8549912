# Sourced by the shell tests that count their checks: a scratch directory $work removed on exit
# (as the program sees it: getcwd resolves links), the tallies, ok/bad for one check each, and
# finish NAME, which prints the tally and returns non-zero when a check failed.
work=$(cd "$(mktemp -d)" && pwd -P)
trap 'rm -rf "$work"' EXIT
passed=0 failed=0
ok() { passed=$((passed + 1)); echo "ok   $1"; }
bad() { failed=$((failed + 1)); echo "FAIL $1"; }
finish() {
  echo "$1$passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}

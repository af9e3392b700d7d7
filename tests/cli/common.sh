# What every command-line test script starts with; sourced as `. common.sh "$@"`:
# cli (the sweepers-cli to test) and data (the data/ directory) from the arguments, the
# Python that has pyopenvdb, a temporary directory removed on exit, fail, and refuses.
set -euo pipefail
cli=$1
data=$2
py=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
# A command that must fail: exit 1 and exactly this line on stderr.
refuses() {
  local expected=$1
  shift
  if "$cli" "$@" 2>"$tmp/err"; then fail "accepted: $*"; fi
  [ "$(cat "$tmp/err")" = "$expected" ] || fail "$*: '$(cat "$tmp/err")', expected '$expected'"
  echo "refused: $expected"
}

# SPDX-License-Identifier: Apache-2.0
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
# Runs a sweepers-cli command in the background, its stderr in ERR, until READY (a shell
# test) holds (10 s at most), then sends it SIGNAL; its exit code is left in rc. For
# stopping long work part way: stopped SIGNAL ERR READY ARGS...
stopped() {
  local signal=$1 err=$2 ready=$3
  shift 3
  "$cli" "$@" 2>"$err" &
  local pid=$!
  for _ in $(seq 1 400); do
    eval "$ready" && break
    sleep 0.025
  done
  kill "-$signal" "$pid" 2>/dev/null || true
  rc=0
  wait "$pid" 2>/dev/null || rc=$?
}
# A command that must fail: exit 1 and exactly this line on stderr.
refuses() {
  local expected=$1
  shift
  if "$cli" "$@" 2>"$tmp/err"; then fail "accepted: $*"; fi
  [ "$(cat "$tmp/err")" = "$expected" ] || fail "$*: '$(cat "$tmp/err")', expected '$expected'"
  echo "refused: $expected"
}

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Writes never destroy good data: a full disk (a small tmpfs, where this user may mount
# one, and a file-size limit, which needs nothing) makes apply, mesh and apply --mesh fail
# with the reason, keep the old files as they were and leave no temporary file; a run
# killed with SIGKILL at any moment leaves the old file or the new one, and the next run
# removes the temporary file it left.
set -euo pipefail
cli=$1
data=$2
tmp=$(mktemp -d)
mnt=$tmp/small
cleanup() {
  mountpoint -q "$mnt" 2>/dev/null && umount "$mnt"
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }

no_temp_left() {
  if compgen -G "$1/*.tmp-*" >/dev/null; then
    ls -la "$1"
    fail "$2: a temporary file was left behind"
  fi
}

# Runs "$@" expecting failure with `reason` on stderr, the files under $dir unchanged
# (their checksums in $dir.sums) and no temporary file.
expect_refused() {
  local dir=$1 reason=$2
  shift 2
  if "$@" 2>"$tmp/err" >/dev/null; then
    fail "$* succeeded on a full disk"
  fi
  grep -q "$reason" "$tmp/err" || fail "$*: expected '$reason', got: $(cat "$tmp/err")"
  [ "$(wc -l <"$tmp/err")" -le 2 ] || fail "$*: more than a line or two of error: $(cat "$tmp/err")"
  (cd "$dir" && sha256sum -c --quiet "$tmp/sums") || fail "$*: an old file changed"
  no_temp_left "$dir" "$*"
}

# Good files first, then every write that cannot fit.
full_disk_checks() {
  local dir=$1 reason=$2
  shift 2
  local limit=("$@") # a command prefix that makes writes fail
  (cd "$dir" && sha256sum ./*.vdb ./*.ply >"$tmp/sums")
  expect_refused "$dir" "$reason" "${limit[@]}" "${run[@]}" -o "$dir/good.vdb"
  expect_refused "$dir" "$reason" "${limit[@]}" "$cli" mesh "$tmp/big.vdb" -o "$dir/good.ply"
  expect_refused "$dir" "$reason" "${limit[@]}" "${run[@]}" -o "$dir/new.vdb" --mesh "$dir/new.ply"
  [ ! -e "$dir/new.vdb" ] || fail "apply --mesh left a grid behind when its mesh failed"
}

"$cli" new -o "$tmp/big.vdb" --voxel-size 0.01 # about 3 MB, and a mesh of about 5 MB
run=("$cli" apply "$data/pull.json" -q --voxel-size 0.015) # 1.8 MB written (1.3 s under ASan)

# --- a file-size limit: every write past 256 KiB fails (EFBIG) -------------------------
mkdir "$tmp/limited"
"$cli" new -o "$tmp/limited/good.vdb" --voxel-size 0.1
"$cli" mesh "$tmp/limited/good.vdb" -o "$tmp/limited/good.ply" 2>/dev/null
full_disk_checks "$tmp/limited" "File too large" bash -c 'trap "" XFSZ; ulimit -f 256; exec "$@"' limit

# --- a full file system: a 1 MiB tmpfs ------------------------------------------------
mkdir "$mnt"
if mount -t tmpfs -o size=1m tmpfs "$mnt" 2>/dev/null; then
  "$cli" new -o "$mnt/good.vdb" --voxel-size 0.1
  "$cli" mesh "$mnt/good.vdb" -o "$mnt/good.ply" 2>/dev/null
  full_disk_checks "$mnt" "No space left on device"
else
  echo "skipped the tmpfs case: this user cannot mount one (the file-size limit case ran)"
fi

# --- SIGKILL at random moments over a good file ------------------------------------------
mkdir "$tmp/killed"
out=$tmp/killed/out.vdb
"$cli" new -o "$tmp/old.vdb" --voxel-size 0.1
old=$("$cli" info "$tmp/old.vdb" | grep -o '[0-9]* active voxels')
# The kills fall anywhere in the run, its write included, however fast this build is: at
# moments spread over 0 to 1.1 times the run's own time (in microseconds).
start=${EPOCHREALTIME/./}
"${run[@]}" -o "$tmp/new.vdb"
took=$((${EPOCHREALTIME/./} - start))
new=$("$cli" info "$tmp/new.vdb" | grep -o '[0-9]* active voxels')
RANDOM=11 # the same fractions every run
olds=0
news=0
for i in $(seq 16); do
  cp "$tmp/old.vdb" "$out"
  "${run[@]}" -o "$out" &
  pid=$!
  delay=$((took * (RANDOM % 1100) / 1000))
  sleep "$((delay / 1000000)).$(printf '%06d' $((delay % 1000000)))"
  kill -9 "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  now=$("$cli" info "$out" | grep -o '[0-9]* active voxels') || fail "kill $i: $out is unreadable"
  if [ "$now" = "$old" ]; then
    olds=$((olds + 1))
  elif [ "$now" = "$new" ]; then
    news=$((news + 1))
  else
    fail "kill $i: $out holds $now, neither $old nor $new"
  fi
done
echo "SIGKILL: $olds runs killed before their rename (old file kept), $news finished"
"${run[@]}" -o "$out"
no_temp_left "$tmp/killed" "the run after the killed ones"
echo "writes: full disk and SIGKILL checks passed"

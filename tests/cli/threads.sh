#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The same grid, voxel for voxel, whatever the number of threads: a drag, a swirl, a pinch
# and a flow applied at 1, 2, 3 and 7 threads (7 oversubscribes a small machine on purpose,
# so that the work is split and scheduled in other ways), compared with pyopenvdb.
. "$(dirname "$0")/common.sh" "$@"
same=$(dirname "$0")/../app/same_grid.py
for case in "drag.json 0.03125" "starfish_swirls.json 0.03125" "pinch.json 0.03125" \
  "flows/enright.json 0.02"; do
  read -r script h <<<"$case"
  name=$(basename "$script" .json)
  for n in 1 2 3 7; do
    "$cli" --threads "$n" apply "$data/$script" -o "$tmp/${name}_$n.vdb" --voxel-size "$h" -q
  done
  for n in 2 3 7; do
    "$py" "$same" "$tmp/${name}_1.vdb" "$tmp/${name}_$n.vdb" >/dev/null ||
      fail "$script at voxel size $h: $n threads give another grid than one thread"
  done
  echo "$script: the same grid at 1, 2, 3 and 7 threads"
done
echo "threads: all checks passed"

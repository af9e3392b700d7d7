#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# sweepers-cli study --slurm on a real one-node Slurm cluster started for this test and
# stopped after it (tests/cli/slurm_cluster.sh): its table equals the local run's, a failed
# run is named and the others merged, a task cancelled mid-run leaves no partial result and
# submitting again runs only it, a second submission while the first is queued is refused,
# and without sbatch nothing is submitted. Where no cluster can be started (not root), it
# says why and is skipped (exit 77).
. "$(dirname "$0")/common.sh" "$@"
. "$(dirname "$0")/slurm_cluster.sh"
same() { "$py" "$(dirname "$0")/same_table.py" "$1/study.csv" "$2/study.csv"; }

# --- without sbatch: one line, nothing planned or submitted ------------------------------
rc=0
PATH=/nonexistent "$cli" study "$data/studies/rigid_motion.json" -o "$tmp/nosbatch" --slurm \
  2>"$tmp/err" || rc=$?
[ "$rc" = 1 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "sbatch is not installed" "$tmp/err" ||
  fail "--slurm without sbatch: exit $rc, '$(cat "$tmp/err")'"
[ ! -e "$tmp/nosbatch" ] || fail "--slurm without sbatch wrote $tmp/nosbatch"
echo "without sbatch: $(cat "$tmp/err")"

trap 'stop_cluster; rm -rf "$tmp"' EXIT
if ! start_cluster; then
  echo "SKIPPED: the Slurm tests need a cluster"
  exit 77
fi
echo "a one-node cluster: $(sinfo -h -o '%P %D %c %m %T')"

# --- 2 scripts x 3 voxel sizes x 2 variants: the cluster's table is the local one -------
two=("$data/studies/rigid_motion.json" "$data/twisted_limb.json")
sizes=(--voxel-sizes 1/8,1/16,1/32 --variants trilinear,cubic)
"$cli" study "${two[@]}" -o "$tmp/local" "${sizes[@]}" -q
"$cli" study "${two[@]}" -o "$tmp/slurm" "${sizes[@]}" --slurm --wait --max-running 2 \
  --partition test --sbatch-arg=--comment=sweepers-test 2>"$tmp/err" || fail "--slurm --wait: $(cat "$tmp/err")"
same "$tmp/local" "$tmp/slurm"
grep -q "12 runs (0 reused from before, 0 failed)" "$tmp/err" || fail "summary: $(cat "$tmp/err")"
"$py" - "$tmp/slurm" <<'PY'
import json, os, re, sys
d = sys.argv[1]
jobs = json.load(open(f"{d}/slurm/jobs.json"))
# The first runs of the two coarsest voxel sizes of each script ran here to estimate the
# others; the rest went to the cluster in one array per voxel size, each asking for memory
# and time.
arrays = jobs["arrays"]
assert [a["runs"] for a in arrays] == [
    ["rigid_motion-cubic_8", "twisted_limb-cubic_8"],
    ["rigid_motion-cubic_16", "twisted_limb-cubic_16"],
    ["rigid_motion-trilinear_32", "rigid_motion-cubic_32", "twisted_limb-trilinear_32",
     "twisted_limb-cubic_32"]], arrays
assert all(a["mem_mb"] > 256 and a["time_minutes"] >= 5 for a in arrays), arrays
# Their estimates scaled from the finest of those: the time by growth rates fitted to the
# two (between 1/h^2 and 1/h^3: 4 to 8 times the run at twice the voxel size).
plan = {r["id"]: r["estimate"] for r in json.load(open(f"{d}/plan.json"))["runs"]}
for script in ("rigid_motion", "twisted_limb"):
    coarse, fine = plan[f"{script}-trilinear_16"], plan[f"{script}-trilinear_32"]
    assert fine["basis"] == f"measured run {script}-trilinear_16", fine
    assert 4 * (1 - 1e-9) < fine["seconds"] / coarse["seconds"] < 8 * (1 + 1e-9), (coarse, fine)
    assert fine["memory_mb"] >= coarse["memory_mb"], (coarse, fine)
runs = open(f"{d}/slurm/runs.sbatch").read()
assert re.search(r"^#SBATCH --array=1,3,4,5,7,9,10,11%2$", runs, re.M), runs
assert "#SBATCH --comment=sweepers-test" in runs and "--cpus-per-task=1" in runs, runs
assert "#SBATCH --partition=test" in runs, runs
merge = open(f"{d}/slurm/merge.sbatch").read()
assert "--merge" in merge, merge
logs = os.listdir(f"{d}/slurm/logs")
assert len([l for l in logs if not l.startswith("merge")]) == 8, logs
report = open(f"{d}/report.md").read()
assert "## Runs without a result" not in report and report.count("| done |") == 12, report
print("cluster: three arrays (1/8, 1/16, 1/32) of", [len(a["runs"]) for a in arrays],
      "runs, merged")
PY

# --- a run that fails: named in the report and the exit, the others merged --------------
# A VDB start keeps its own voxel size (1/16): the run at 1/8 is refused.
"$cli" new -o "$tmp/ball.vdb" --radius 0.5 --voxel-size 0.0625
cat >"$tmp/own.json" <<'JSON'
{"sweepers": 1, "start": {"vdb": "ball.vdb"},
 "strokes": [{"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3,
   "path": [{"t": [0, 0.5, 0]}, {"t": [0, 0.7, 0]}]}]}]}
JSON
rc=0
"$cli" study "$tmp/own.json" -o "$tmp/failing" --voxel-sizes 1/8,1/16 --slurm --wait \
  2>"$tmp/err" || rc=$?
[ "$rc" = 3 ] || fail "a study with a failed run exited $rc: $(cat "$tmp/err")"
grep -q "sweepers-cli: 1 of 2 runs failed (own-corrected_8)" "$tmp/err" ||
  fail "the failed run is not named: $(cat "$tmp/err")"
grep -q "| corrected | 1/8 | failed: " "$tmp/failing/report.md" ||
  fail "report.md does not name the failed run"
grep -q "| corrected | 1/16 | " "$tmp/failing/report.md" || fail "the other run was not merged"
echo "a failed run: exit 3, named; the other merged"

# --- a task cancelled mid-run; a second submission refused; submitting again ------------
long=(--voxel-sizes 1/16,1/96)
"$cli" study "$data/twisted_limb.json" -o "$tmp/cancel" "${long[@]}" --slurm -q >"$tmp/ids"
array=$(awk '/^arrays/ {print $2}' "$tmp/ids")
merge=$(awk '/^merge/ {print $2}' "$tmp/ids")
run=twisted_limb-corrected_96
rc=0
"$cli" study "$data/twisted_limb.json" -o "$tmp/cancel" "${long[@]}" --slurm 2>"$tmp/err" || rc=$?
[ "$rc" = 1 ] && grep -q "still queued or running" "$tmp/err" ||
  fail "a second submission while the first runs: exit $rc, $(cat "$tmp/err")"
# Mid-run: its first segment is done (its log says so), the others are not.
log="$tmp/cancel/slurm/logs/${array}_1.out"
for _ in $(seq 1 1200); do
  grep -q "segment 1 / " "$log" 2>/dev/null && break
  sleep 0.05
done
grep -q "segment 1 / " "$log" || fail "the run did not start: $(squeue)"
scancel "${array}_1"
for _ in $(seq 1 600); do
  state=$(scontrol show job -o "$merge" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
  [ "$state" = COMPLETED ] || [ "$state" = FAILED ] && break
  sleep 0.1
done
[ "$state" = COMPLETED ] || [ "$state" = FAILED ] || fail "the merge did not run: $state"
[ ! -e "$tmp/cancel/runs/$run/result.json" ] || fail "a cancelled run left a result"
[ ! -e "$tmp/cancel/runs/$run/grid.vdb" ] || fail "a cancelled run left a grid"
if find "$tmp/cancel" -name "*.tmp-*" | grep -q .; then
  fail "temporary files left: $(find "$tmp/cancel" -name "*.tmp-*")"
fi
grep -A4 "## Runs without a result" "$tmp/cancel/report.md" | grep -q -- "- $run" ||
  fail "report.md does not name the cancelled run"
"$cli" study "$data/twisted_limb.json" -o "$tmp/cancel" "${long[@]}" --slurm --wait \
  2>"$tmp/err" || fail "submitting again: $(cat "$tmp/err")"
"$py" - "$tmp/cancel" "$run" <<'PY'
import json, sys
d, run = sys.argv[1:]
arrays = json.load(open(f"{d}/slurm/jobs.json"))["arrays"]
assert [a["runs"] for a in arrays] == [[run]], arrays  # only the run without a result
report = open(f"{d}/report.md").read()
assert "## Runs without a result" not in report and report.count("| done |") == 2, report
print("cancelled mid-run: no partial result; submitted again, only it ran; report complete")
PY
echo "slurm: all checks passed"

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What sweepers-cli prints, as scripts and pipes see it: progress as whole lines in a pipe
# and as one line redrawn on a terminal, -q silent but for errors, --json one object on
# stdout with the documented keys, and every documented exit code (docs/cli.md).
. "$(dirname "$0")/common.sh" "$@"

# --- a pipe: one progress event per line, never two glued -----------------------------
"$cli" apply "$data/two_handles.json" -o "$tmp/th.vdb" --voxel-size 0.05 2>&1 | cat >"$tmp/piped"
"$py" - "$tmp/piped" <<'PY'
import re, sys
text = open(sys.argv[1], "rb").read().decode()
assert "\r" not in text and "\x1b" not in text, "terminal control codes in a pipe: %r" % text[:200]
lines = text.splitlines()
progress = [l for l in lines if l.startswith("applying ")]
pattern = re.compile(r"applying \S+two_handles.json: segment (\d+) / 32 \(\d+%, [^)]*\)$")
for l in progress:
    assert pattern.match(l), "not one progress event: %r" % l
others = [l for l in lines if not l.startswith("applying ")]
assert len(others) == 1 and others[0].startswith("wrote "), others
counts = [int(pattern.match(l).group(1)) for l in progress]
assert counts == sorted(counts) and counts[-1] == 32, counts
# A line per tenth of the work, not one per segment.
assert 5 <= len(progress) <= 11, len(progress)
print("pipe: %d progress lines, one event each, then the result" % len(progress))
PY

# --- a terminal (a pseudo-terminal from script(1)): one line redrawn in place ----------
script -qec "'$cli' apply '$data/drag.json' -o '$tmp/tty.vdb' --voxel-size 0.05" /dev/null \
  >"$tmp/tty" </dev/null
"$py" - "$tmp/tty" <<'PY'
import sys
text = open(sys.argv[1], "rb").read().decode()
lines = text.replace("\r\n", "\n").split("\n")
bar = [l for l in lines if "\r\x1b[K" in l]
assert len(bar) == 1, "the bar is not one line redrawn: %r" % text[:300]
draws = bar[0].split("\r\x1b[K")[1:]
assert all("[" in d and "segment" in d for d in draws), draws
assert draws[-1].split("] ")[1].startswith("segment 100 / 100"), draws[-1]
assert any(l.startswith("wrote ") for l in lines), lines
print("terminal: %d draws of one line, ending at 100 / 100" % len(draws))
PY

# --- -q: nothing but errors -------------------------------------------------------------
quiet_run() {
  "$cli" "$@" >"$tmp/q.out" 2>"$tmp/q.err" || fail "-q $*: exit $?"
  [ ! -s "$tmp/q.err" ] || fail "-q $* printed on stderr: $(head -3 "$tmp/q.err")"
}
quiet_run apply "$data/drag.json" -o "$tmp/q.vdb" --voxel-size 0.05 --mesh "$tmp/q.ply" -q
[ ! -s "$tmp/q.out" ] || fail "apply -q printed on stdout"
quiet_run -q mesh "$tmp/q.vdb" -o "$tmp/q.obj"
quiet_run study "$data/studies/rigid_motion.json" -o "$tmp/qs" --voxel-sizes 1/8 -q
quiet_run animate "$data/animation/keyframed_grab.json" -o "$tmp/qf/f_##.vdb" --voxel-size 0.05 \
  --frames 1-3 -q
echo "-q: nothing on stderr from apply, mesh, study and animate"

# --- --json: one object on stdout holding the documented keys ---------------------------
json_keys() { # json_keys FILE KEY... : stdout parses as one object holding these keys
  "$py" - "$@" <<'PY'
import json, sys
obj = json.load(open(sys.argv[1]))
assert isinstance(obj, dict), type(obj)
missing = [k for k in sys.argv[2:] if k not in obj]
assert not missing, "missing %s in %s" % (missing, sorted(obj))
PY
}
"$cli" apply "$data/drag.json" -o "$tmp/j.vdb" --voxel-size 0.05 --mesh "$tmp/j.ply" --json \
  >"$tmp/apply.json" 2>/dev/null
json_keys "$tmp/apply.json" script output mesh files segments voxel_size active_voxels volume \
  volume_before volume_change_pct area topology timings
"$py" - "$tmp/apply.json" "$tmp/j.vdb" "$tmp/j.ply" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["files"] == sys.argv[2:4], j["files"]
assert j["topology"] == {"euler_characteristic": 2, "genus": 0, "components": 1}, j["topology"]
assert j["mesh"]["triangles"] > 1000 and j["segments"] == 100, j
assert 0 < j["volume_change_pct"] < 5, j["volume_change_pct"]
assert set(j["timings"]) == {"wall_s", "band_growth_s", "sampling_s", "renormalization_s"}
PY
"$cli" info "$tmp/j.vdb" --json >"$tmp/info.json"
json_keys "$tmp/info.json" file grid voxel_size active_voxels volume area genus components \
  euler_characteristic mesh_volume mesh_triangles
"$cli" check "$data/pull.json" --json >"$tmp/check.json"
json_keys "$tmp/check.json" script valid strokes voxel_size deformations
# In the tree it was built in, --help names the checkout's examples and guides.
"$cli" --help >"$tmp/help"
grep -qx "Examples: $data (sweepers-cli apply $data/horn.json -o horn.vdb)" "$tmp/help" ||
  fail "--help: $(tail -2 "$tmp/help")"
grep -qx "Guides: $(dirname "$data")/README.md and docs/ beside it (cli.md, stroke-scripts.md, studies.md)" \
  "$tmp/help" || fail "--help: $(tail -2 "$tmp/help")"
# `examples` prints the same folder, the one the docs' $(sweepers-cli examples) names.
[ "$("$cli" examples)" = "$data" ] || fail "examples: $("$cli" examples)"
"$cli" study "$data/studies/rigid_motion.json" -o "$tmp/js" --voxel-sizes 1/8,1/16 --json \
  >"$tmp/study.json" 2>/dev/null
json_keys "$tmp/study.json" script dir csv report runs reused failed files
"$py" - "$tmp/study.json" <<'PY'
import csv, json, sys
j = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(j["csv"])))
assert [r["variant"] for r in j["runs"]] == [r["variant"] for r in rows] == ["corrected"] * 2
for r, c in zip(j["runs"], rows):
    assert set(r) == set(c), set(r) ^ set(c)  # the CSV's columns, no more, no fewer
    assert r["err_rms"] == float(c["err_rms"]) and r["genus"] == int(c["genus"]) == 0, (r, c)
PY
"$cli" animate "$data/animation/keyframed_grab.json" -o "$tmp/jf/f_####.vdb" --voxel-size 0.05 \
  --frames 2-4 --json >"$tmp/animate.json" 2>/dev/null
json_keys "$tmp/animate.json" script frames fps seconds voxel_size written kept files
"$py" - "$tmp/animate.json" <<'PY'
import json, os, sys
j = json.load(open(sys.argv[1]))
assert j["written"] == 3 and j["frames"]["first"] == 2 and j["frames"]["last"] == 4, j
assert all(os.path.exists(f) for f in j["files"]) and len(j["files"]) == 3, j["files"]
PY
echo "--json: apply, info, check, study and animate print one object with their keys"

# --- --stats: a row per segment, with its serial time (what more cores cannot shorten) ----
"$cli" --threads 1 apply "$data/drag.json" -o "$tmp/s.vdb" --voxel-size 0.05 --stats -q \
  2>"$tmp/stats"
"$py" - "$tmp/stats" <<'PY'
import sys
lines = [l.split() for l in open(sys.argv[1])]
head = next(l for l in lines if l and l[0] == "stroke")
rows = [dict(zip(head, l)) for l in lines if len(l) == len(head) and l[0].isdigit()]
assert len(rows) == 100, len(rows)
for r in rows:
    stages = sum(float(r[k]) for k in ("grow_ms", "sample_ms", "renorm_ms", "mesh_ms"))
    serial = float(r["serial_ms"])
    # At one thread the serial time is the segment's time outside its parallel loops (and
    # their overhead): never negative, never more than the segment (a stage's figures are
    # rounded to 0.1 ms; the set-up around the stages is serial too).
    assert 0.0 <= serial <= stages + 1.0, r
print("--stats: serial_ms in each of the %d rows" % len(rows))
PY

# --- exit codes ---------------------------------------------------------------------------
code() { # code EXPECTED ARGS... : the command exits EXPECTED
  local expected=$1 rc=0
  shift
  "$cli" "$@" >/dev/null 2>"$tmp/code.err" || rc=$?
  [ "$rc" = "$expected" ] || fail "$*: exit $rc, expected $expected ($(head -2 "$tmp/code.err"))"
}
code 0 check "$data/pull.json"
code 0 --help
code 1 apply "$tmp/missing.json" -o "$tmp/m.vdb"            # input refused
code 1 info "$tmp/apply.json"                                # not a VDB
code 2 apply "$data/pull.json"                               # -o missing
code 2 apply "$data/pull.json" -o "$tmp/u.vdb" --voxel-size -1
code 2 frobnicate
code 2 study "$data/studies/rigid_motion.json" -o "$tmp/u" --voxel-sizes 1/32,fine
code 2 animate "$data/animation/keyframed_grab.json" -o "$tmp/u_#.vdb" --frames 9-3
stopped INT "$tmp/int.err" '[ -s "$tmp/int.err" ]' apply "$data/drag.json" -o "$tmp/int.vdb" \
  --voxel-size 0.0078125
[ "$rc" = 130 ] || fail "apply stopped by SIGINT exited $rc"
# A study whose runs partly fail: a VDB start keeps its own voxel size, so the run at
# another size is refused while the one at the file's own runs.
"$cli" new -o "$tmp/ball.vdb" --radius 0.5 --voxel-size 0.0625
cat >"$tmp/own.json" <<'JSON'
{"sweepers": 1, "start": {"vdb": "ball.vdb"},
 "strokes": [{"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": 0.3,
   "path": [{"t": [0, 0.5, 0]}, {"t": [0, 0.7, 0]}]}]}]}
JSON
rc=0
"$cli" study "$tmp/own.json" -o "$tmp/partly" --voxel-sizes 0.125,0.0625 2>"$tmp/partly.err" || rc=$?
[ "$rc" = 3 ] || fail "a study with a failed run exited $rc: $(cat "$tmp/partly.err")"
grep -q 'sweepers-cli: 1 of 2 runs failed (own-corrected_8)' "$tmp/partly.err" ||
  fail "the failed run is not named: $(cat "$tmp/partly.err")"
[ -s "$tmp/partly/runs/own-corrected_16/grid.vdb" ] || fail "the run that could run was not written"
grep -q '| corrected | 1/8 | failed: ' "$tmp/partly/report.md" ||
  fail "report.md does not name the failed run"
echo "exit codes: 0, 1, 2, 3 (a study with a failed run) and 130 (SIGINT)"
echo "output: all checks passed"

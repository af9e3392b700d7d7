#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Input a hostile user gives (issue cases of "bad input never hurts"): what is not a regular
# file in a file's place, a script without end, option values that make no sense, a film
# without bound, and errors asked for as JSON. Each is refused at once, with one line that
# says why, and leaves nothing behind; none may hang (every command runs under a timeout).
. "$(dirname "$0")/common.sh" "$@"
cd "$tmp"
# A refusal with exit `code`, one line on stderr containing `message`, within 20 s.
refused() {
  local code=$1 message=$2
  shift 2
  local rc=0
  timeout 20 "$cli" "$@" >out 2>err || rc=$?
  [ "$rc" = "$code" ] || fail "$*: exit $rc, expected $code ($(cat err))"
  grep -qF -- "$message" err || fail "$*: expected '$message', got: $(cat err)"
  echo "refused ($rc): $(head -1 err)"
}
"$cli" new -o sphere.vdb --radius 0.5 --voxel-size 0.05
printf '{"sweepers": 1, "grid": {"voxel_size": 0.05}, "start": {"sphere": {"center": [0, 0, 0], "radius": 0.5}}, "strokes": []}' >script.json

# Not regular files: a FIFO (opening one waits for a writer), a directory, a device.
mkfifo fifo.vdb fifo.json fifo.obj
refused 1 "fifo.vdb: not a regular file (a FIFO)" info fifo.vdb
refused 1 "fifo.json: not a regular file (a FIFO)" apply fifo.json -o out.vdb
refused 1 "fifo.json: not a regular file (a FIFO)" check fifo.json
refused 1 "fifo.obj: not a regular file (a FIFO)" mesh fifo.obj -o out.ply
mkdir dir.vdb
refused 1 "dir.vdb: not a regular file (a directory)" info dir.vdb
refused 1 "/dev/zero: not a regular file (a character device)" apply /dev/zero -o out.vdb
printf '{"sweepers": 1, "start": {"vdb": "fifo.vdb"}, "strokes": []}' >fifo_start.json
refused 1 "fifo.vdb: not a regular file (a FIFO)" apply fifo_start.json -o out.vdb
printf '{"sweepers": 1, "start": {"mesh": "fifo.obj"}, "strokes": []}' >fifo_mesh.json
refused 1 "fifo.obj: not a regular file (a FIFO)" apply fifo_mesh.json -o out.vdb
[ ! -e out.vdb ] || fail "a refused apply wrote out.vdb"
# A script beyond the bound is refused before it is read.
truncate -s 65M big.json
refused 1 "big.json: 65 MB; a stroke script holds at most 64 MB" apply big.json -o out.vdb

# A study whose result is a FIFO: the run is run again, its result written in its place.
"$cli" study script.json -q -o study --voxel-sizes 1/8 --plan-only
run=$("$cli" study -o study --list)
mkdir -p "study/runs/$run" && mkfifo "study/runs/$run/result.json"
timeout 60 "$cli" study -q -o study --merge >/dev/null 2>&1 || true # (missing: exit 3)
[ "$(timeout 20 "$cli" study -o study --list)" = "$run" ] || fail "--list with a FIFO result"
timeout 120 "$cli" study -q -o study --run "$run" || fail "the run did not replace the FIFO"
[ -f "study/runs/$run/result.json" ] || fail "no result written over the FIFO"
# An empty run id (a Slurm task missing from its list) is a usage error, not the whole study.
refused 2 "--run: needs a run's id" study -o study --run ''

# Values that make no sense are usage errors, before any work.
refused 2 "--voxel-size must be a positive number, not 0" apply script.json -o out.vdb --voxel-size 0
refused 2 "--voxel-size must be a positive number, not 0" animate script.json -o 'f_#.vdb' --voxel-size 0
refused 2 "--fps: must be a positive number of at most 1000, not 1e9" animate script.json -o 'f_#.vdb' --fps 1e9
refused 2 "'surface' is the level set's own name" animate script.json -o 'f_#.vdb' --fog surface
ls f_* 2>/dev/null && fail "a refused film wrote frames"
refused 2 "--center: must be a number within 1e5 of zero, not nan" new -o nan.vdb --center nan 0 0
refused 2 "--center: must be a number within 1e5 of zero, not 1e7" new -o far.vdb --center 1e7 0 0

# With --json a failure is one JSON object on stdout too: the message and the exit code.
for args in "apply missing.json -o out.vdb" "apply script.json -o out.vdb --voxel-size 0" \
            "info fifo.vdb"; do
  rc=0
  # shellcheck disable=SC2086 # (the words of each command)
  timeout 20 "$cli" $args --json >out 2>err || rc=$?
  "$py" - "$rc" <<'PY' || fail "$args --json: $(cat out)"
import json, sys
said = json.load(open("out"))
line = open("err").read().strip()
assert said["exit"] == int(sys.argv[1]) != 0, said
assert said["error"] and said["error"] in line, (said, line)
PY
done

# A VDB whose transform mirrors (a negative scale) turns every stroke inside out: refused.
# One whose voxel size is a float (as pyopenvdb writes it) is the script's voxel size.
"$py" - <<'PY'
import numpy as np
import pyopenvdb as vdb
g = vdb.createLevelSetSphere(radius=0.5, voxelSize=0.1)
m = np.diag([-0.1, 0.1, 0.1, 1.0])
g.transform = vdb.createLinearTransform(m.tolist())
g.name = "surface"
vdb.write("mirrored.vdb", grids=[g])
far = vdb.createLevelSetSphere(radius=0.5, center=(2e5, 0, 0), voxelSize=0.1)
far.name = "surface"
vdb.write("far.vdb", grids=[far])
f = vdb.createLevelSetSphere(radius=0.5, voxelSize=0.1)
f.name = "surface"
vdb.write("float_size.vdb", grids=[f])
PY
refused 1 "has a mirrored transform" info mirrored.vdb
refused 1 "lies beyond 1e5 of the origin" info far.vdb
printf '{"sweepers": 1, "grid": {"voxel_size": 0.1}, "start": {"vdb": "float_size.vdb"}, "strokes": []}' >float_size.json
"$cli" -q apply float_size.json -o float_out.vdb || fail "a float voxel size of 0.1 was refused"
printf '{"sweepers": 1, "grid": {"voxel_size": 0.1000001}, "start": {"vdb": "float_size.vdb"}, "strokes": []}' >other_size.json
refused 1 "its voxel size 0.100000001" apply other_size.json -o out.vdb
# An inflation far larger than the shape gives what the thesis's inflation gives: its ball,
# the unit sphere's clay on it, one part of genus 0 (radius 10 once gave genus 73).
printf '{"sweepers": 1, "grid": {"voxel_size": 0.0625}, "strokes": [{"type": "inflate", "at": [0, 1, 0], "radius": 5}]}' >big_ball.json
"$cli" -q apply big_ball.json -o big_ball.vdb
"$cli" info --json big_ball.vdb | "$py" -c '
import json, math, sys
info = json.load(sys.stdin)
exact = 4 / 3 * math.pi * (5 ** 3 + 1)  # the ball and the sphere it swallowed
assert info["components"] == 1 and info["genus"] == 0, info
assert abs(info["mesh_volume"] - exact) < 1e-3 * exact, (info["mesh_volume"], exact)
volume = info["mesh_volume"]
print(f"an inflation of radius 5 on the unit sphere: one part, genus 0, volume {volume:.2f} of {exact:.2f}")'

# Work and memory past the limits are refused by estimate, before anything is allocated:
# each refusal's peak memory stays that of a small process.
small() { # small MESSAGE ARGS...: refused with exit 1, naming MESSAGE, under 300 MB
  local message=$1
  shift
  local rc=0
  timeout 60 /usr/bin/time -f %M -o peak "$cli" "$@" >out 2>err || rc=$?
  [ "$rc" = 1 ] || fail "$*: exit $rc, expected 1 ($(cat err))"
  grep -qF -- "$message" err || fail "$*: expected '$message', got: $(cat err)"
  [ "$(tail -1 peak)" -lt 300000 ] || fail "$*: peak $(tail -1 peak) KB before refusing"
  echo "refused at $(($(tail -1 peak) / 1024)) MB: $(head -1 err)"
}
printf '{"sweepers": 1, "grid": {"voxel_size": 0.0625}, "strokes": [{"type": "fluid", "radius": 0.01, "path": [[0, 0.85, 0], [0, 1e5, 0]]}]}' >far_fluid.json
small "flow steps; at most 1e6" apply far_fluid.json -o out.vdb
small "fluid segment 1 of radius 0.3 takes about" --max-work 1e5 apply "$data/fluid/nose_fluid.json" -o out.vdb
printf '{"sweepers": 1, "grid": {"voxel_size": 0.0625}, "strokes": [{"type": "smooth", "tool": {"shape": "ball", "size": 1e4, "falloff": 0.1, "path": [{"t": [0, 1, 0]}]}}]}' >huge_smooth.json
# A smooth dab far larger than the shape is a filter of a few lattice nodes now: it runs at
# once, and moves the surface no more than two voxels. Past the work limit it is refused.
timeout 20 /usr/bin/time -f %M -o peak "$cli" -q apply huge_smooth.json -o huge_smooth.vdb ||
  fail "a smooth dab of radius 1e4 did not run"
[ "$(tail -1 peak)" -lt 300000 ] || fail "a smooth dab of radius 1e4 peaked at $(tail -1 peak) KB"
"$cli" info --json huge_smooth.vdb | "$py" -c '
import json, sys
info = json.load(sys.stdin)
radius = (info["mesh_volume"] * 3 / (4 * 3.14159265)) ** (1 / 3)
assert info["components"] == 1 and 1 - 2.5 * 0.0625 < radius < 1, info
print(f"a smooth dab of radius 1e4 on the unit sphere: its radius is now {radius:.3f}")'
printf '{"sweepers": 1, "grid": {"voxel_size": 0.0625}, "strokes": [{"type": "smooth", "tool": {"shape": "ball", "size": 0.5, "falloff": 0.1, "path": [{"t": [0, 1, 0]}]}}]}' >smooth.json
small "a smooth dab of radius 0.5" --max-work 100 apply smooth.json -o out.vdb
small "applying the script needs about" apply "$data/studies/rigid_motion.json" -o out.vdb --voxel-size 0.000244140625
small "needs about" study "$data/studies/rigid_motion.json" -o big_study --voxel-sizes 1/4096
small "over its limit of 1 MB (--max-memory)" apply "$data/studies/rigid_motion.json" -o out.vdb --max-memory 0.001
printf '{"sweepers": 1, "grid": {"voxel_size": 0.0625}, "strokes": [{"type": "inflate", "at": [0, 1, 0], "radius": 1000}]}' >huge_inflation.json
small "an inflation of radius 1000 needs about" apply huge_inflation.json -o out.vdb
[ ! -e out.vdb ] || fail "a refused apply wrote out.vdb"
echo "hostile: ok"

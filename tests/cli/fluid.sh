#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The swept fluid and sampled velocity fields from the command line: the solution kept in
# the cache directory as a VDB that independent readers see as a staggered vec3s grid and
# read back by the next run; a fluid grab against a sweep on the same
# move; a velocity field written by pyopenvdb carrying a shape; bad velocity files refused in
# one line with nothing written.
. "$(dirname "$0")/common.sh" "$@"
# The test run's cache when it has one (the solve is done once for every test), else ours.
export SWEEPERS_CACHE=${SWEEPERS_CACHE:-$tmp/cache}
cached=$SWEEPERS_CACHE/swept_fluid_72_r12_nu2_dt1.vdb

# --- the cache: solved once, kept, read by others, read back ----------------------------
"$cli" check "$data/fluid/nose_fluid.json" >"$tmp/plan"
grep -q "fluid, 10 sub-steps" "$tmp/plan" || fail "check: $(cat "$tmp/plan")"
[ -s "$cached" ] || fail "the swept fluid was not kept in $cached"
vdb_print -l "$cached" >"$tmp/print" || fail "vdb_print could not read the cached fluid"
grep -q "Tree_vec3s" "$tmp/print" || fail "vdb_print: the cache holds no vec3s grid"
"$py" - "$cached" <<'PY'
import sys, pyopenvdb as vdb
g = vdb.read(sys.argv[1], "velocity")
assert isinstance(g, vdb.Vec3SGrid), type(g)
assert g.gridClass == vdb.GridClass.STAGGERED, g.gridClass
assert g["fluid_cells"] == 72 and g["fluid_ball_radius"] == 12, g.metadata
lo, hi = g.evalActiveVoxelBoundingBox()
assert lo[0] >= 0 and hi[0] <= 72, (lo, hi)
# The ball moves along +x at the centre: face (36, 35, 35) lies inside it.
v = g.getConstAccessor().getValue((36, 35, 35))
assert 0.5 < v[0] < 1.0 and abs(v[1]) < 1e-4, v
PY
before=$(stat -c %Y.%s "$cached")
sleep 1
"$cli" check "$data/fluid/nose_fluid.json" >/dev/null
[ "$(stat -c %Y.%s "$cached")" = "$before" ] || fail "the cached fluid was solved again"
# (A damaged cache, one solved with other parameters, or one that cannot be written: the
# unit tests, on small solutions.)

# --- a fluid grab keeps the volume a sweep on the same move gains -------------------------
for kind in fluid sweep; do
  "$cli" apply "$data/fluid/nose_$kind.json" -o "$tmp/$kind.vdb" --voxel-size 0.0625 2>"$tmp/$kind.log"
done
"$py" - "$tmp/fluid.log" "$tmp/sweep.log" <<'PY'
import re, sys
def change(path):
    return float(re.search(r"volume .* \(([-+0-9.]+)%\)", open(path).read()).group(1))
fluid, sweep = change(sys.argv[1]), change(sys.argv[2])
print(f"nose at 1/16: fluid {fluid:+.3f}%, sweep {sweep:+.3f}%")
assert abs(fluid) < 1.0 and 4 * abs(fluid) < abs(sweep), (fluid, sweep)
PY

# --- a velocity field written by another tool carries the shape ---------------------------
"$py" - "$tmp" <<'PY'
import sys, math, pyopenvdb as vdb
tmp = sys.argv[1]
def field(name, value, background=(0, 0, 0)):
    g = vdb.Vec3SGrid(background)
    g.name = "v"
    g.transform = vdb.createLinearTransform(voxelSize=0.1)
    acc = g.getAccessor()
    for i in range(-12, 13):
        for j in range(-12, 13):
            for k in range(-12, 13):
                acc.setValueOn((i, j, k), value(0.1 * i, 0.1 * j, 0.1 * k))
    vdb.write(f"{tmp}/{name}.vdb", grids=[g])
w = math.pi / 2
field("turn", lambda x, y, z: (-w * y, w * x, 0))
field("nan", lambda x, y, z: (float("nan") if (x, y, z) == (0, 0, 0) else 0, 0, 0))
field("wind", lambda x, y, z: (1, 0, 0), background=(1, 0, 0))
PY
cat >"$tmp/turn.json" <<'JSON'
{ "sweepers": 1, "grid": { "voxel_size": 0.03125 },
  "start": { "sphere": { "center": [0.45, 0, 0.1], "radius": 0.35 } },
  "strokes": [ { "type": "flow", "field": { "vdb": "turn.vdb", "grid": "v" }, "from": 0, "to": 1 } ] }
JSON
"$cli" apply "$tmp/turn.json" -o "$tmp/turned.vdb" 2>"$tmp/log"
"$cli" info --json "$tmp/turned.vdb" >"$tmp/info"
"$py" - "$tmp/info" <<'PY'
import json, sys
info = json.load(open(sys.argv[1]))
lo, hi = info["bbox"]
centre = [(a + b) / 2 for a, b in zip(lo, hi)]
print("turned a quarter turn about z: centre", centre)
assert abs(centre[0]) < 0.04 and abs(centre[1] - 0.45) < 0.04, centre
PY

# --- bad velocity files: one line, non-zero exit, nothing written -------------------------
"$cli" new -o "$tmp/sphere.vdb" --radius 0.5 --voxel-size 0.05
printf 'not a vdb' >"$tmp/junk.vdb"
bad() { # bad FIELD EXPECTED: a flow by FIELD is refused with EXPECTED after the JSON location
  sed "s|\"field\": { \"vdb\": \"turn.vdb\", \"grid\": \"v\" }|\"field\": $1|" "$tmp/turn.json" >"$tmp/bad.json"
  refuses "sweepers-cli: $tmp/bad.json: /strokes/0/field/vdb: $2" apply "$tmp/bad.json" -o "$tmp/no.vdb"
}
bad '{ "vdb": "sphere.vdb" }' \
  "$tmp/sphere.vdb: no velocity grid (vec3s) in the file (it holds 'surface' (float, level set))"
bad '{ "vdb": "sphere.vdb", "grid": "surface" }' \
  "$tmp/sphere.vdb: grid 'surface' (float, level set) is not a velocity grid (vec3s)"
bad '{ "vdb": "nan.vdb" }' \
  "$tmp/nan.vdb: velocity grid 'v' holds 1 velocities that are not finite numbers"
bad '{ "vdb": "wind.vdb" }' \
  "$tmp/wind.vdb: velocity grid 'v' has a background velocity that is not zero (inactive voxels must be at rest)"
bad '{ "vdb": "turn.vdb", "grid": "w" }' \
  "$tmp/turn.vdb: no grid named 'w' (it holds 'v' (vec3s, unknown))"
bad '{ "vdb": "missing.vdb" }' "$tmp/missing.vdb: cannot open the file"
[ ! -e "$tmp/no.vdb" ] || fail "a refused velocity file let a result be written"
sed 's|"field": { "vdb": "turn.vdb", "grid": "v" }|"field": { "vdb": "junk.vdb" }|' "$tmp/turn.json" >"$tmp/bad.json"
if "$cli" apply "$tmp/bad.json" -o "$tmp/no.vdb" 2>"$tmp/err"; then fail "a junk velocity file was read"; fi
[ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "junk.vdb: not a readable VDB file" "$tmp/err" ||
  fail "junk velocity file: $(cat "$tmp/err")"
[ ! -e "$tmp/no.vdb" ] || fail "a junk velocity file let a result be written"

echo "fluid cli: ok"

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# sweepers-cli end to end: real scripts in, VDB and meshes out, read back by independent
# readers (vdb_print from libopenvdb-tools, pyopenvdb under Debian's python3); every
# failure path exits non-zero with one line on stderr and leaves no output file.
. "$(dirname "$0")/common.sh" "$@"

# --- new, read by vdb_print and pyopenvdb ------------------------------------------
"$cli" new -o "$tmp/sphere.vdb" --radius 0.5 --voxel-size 0.025
vdb_print -l "$tmp/sphere.vdb" >"$tmp/print" || fail "vdb_print could not read the file"
grep -q "surface" "$tmp/print" || fail "vdb_print: no grid named surface"
grep -q "level set" "$tmp/print" || fail "vdb_print: not a level set"
version=$("$cli" --version)
[ "${version%% *}" = "sweepers-cli" ] || fail "--version printed '$version'"
"$py" - "$tmp/sphere.vdb" "sweepers ${version#* }" <<'PY'
import sys, pyopenvdb as vdb
grids, meta = vdb.readAll(sys.argv[1])
assert len(grids) == 1, grids
g = grids[0]
assert g.name == "surface", g.name
assert g.gridClass == vdb.GridClass.LEVEL_SET, g.gridClass
assert abs(g.transform.voxelSize()[0] - 0.025) < 1e-12, g.transform.voxelSize()
assert abs(g.background - 3 * 0.025) < 1e-7, g.background
assert g["creator"] == sys.argv[2], (g.metadata, sys.argv[2])
PY

# --- the background reads back as the band's half-width at least ----------------------
# (OpenVDB's checkLevelSet and tools divide it by the voxel size: a float nearest 3 x 0.02
# reads back as 2.99999993 voxels.) Voxel sizes where the float nearest the product lies
# below it, and half-widths 3 and 5.
for hw in 3 5; do
  "$py" - "$data/pull.json" "$tmp/pull_$hw.json" "$hw" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["grid"]["half_width"] = float(sys.argv[3])
json.dump(s, open(sys.argv[2], "w"))
PY
  for h in 0.02 0.07 0.011; do
    "$cli" apply "$tmp/pull_$hw.json" -o "$tmp/bg.vdb" --voxel-size "$h" -q
    "$py" - "$tmp/bg.vdb" "$hw" "$h" <<'PY' || fail "background at half-width $hw, voxel size $h"
import sys, pyopenvdb as vdb
g = vdb.read(sys.argv[1], "surface")
width = g.background / g.transform.voxelSize()[0]
assert width >= float(sys.argv[2]), (sys.argv[2:], g.background, width)
PY
  done
done
echo "background: at least the half-width at voxel sizes 0.02, 0.07, 0.011, half-widths 3 and 5"

# --- `new` writes spheres OpenVDB's checkLevelSet accepts (all nine tests) ----------------
for hw in 3 5; do
  for h in 0.02 0.07 0.011; do
    "$cli" new -o "$tmp/new.vdb" --voxel-size "$h" --half-width "$hw" --radius 0.6 -q
    check=$("$cli" info --json "$tmp/new.vdb" | "$py" -c 'import json, sys; print(json.load(sys.stdin)["openvdb_check"])')
    [ -z "$check" ] || fail "new at voxel size $h, half-width $hw: checkLevelSet says: $check"
  done
done
echo "new: checkLevelSet accepts its spheres at voxel sizes 0.02, 0.07, 0.011, half-widths 3 and 5"

# --- apply a real script, export a mesh, check the numbers --------------------------
"$cli" apply "$data/horn.json" -o "$tmp/horn.vdb" --voxel-size 0.03125 --mesh "$tmp/horn.stl" 2>"$tmp/log"
grep -q "volume" "$tmp/log" || fail "apply printed no volume"
grep -q "segment 4 / 4" "$tmp/log" || fail "apply showed no progress"
[ -s "$tmp/horn.stl" ] || fail "no mesh written"
# STL's facet normals are the facets' own (CAD tools and slicers read them), not averages
# of the vertex normals around them.
"$py" - "$tmp/horn.stl" <<'PY' || fail "STL facet normals"
import math, struct, sys
data = open(sys.argv[1], "rb").read()
n = struct.unpack_from("<I", data, 80)[0]
assert len(data) == 84 + 50 * n, (len(data), n)
worst = 0.0
for f in range(n):
    v = struct.unpack_from("<12f", data, 84 + 50 * f)
    nrm, a, b, c = v[0:3], v[3:6], v[6:9], v[9:12]
    u = [b[i] - a[i] for i in range(3)]
    w = [c[i] - a[i] for i in range(3)]
    x = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    lx, ln = math.sqrt(sum(t * t for t in x)), math.sqrt(sum(t * t for t in nrm))
    if lx == 0:
        continue
    cos = sum(x[i] * nrm[i] for i in range(3)) / (lx * ln)
    worst = max(worst, math.degrees(math.acos(max(-1.0, min(1.0, cos)))))
assert worst < 0.05, "a facet normal is %.3f degrees off its facet" % worst
PY
"$cli" info --json "$tmp/horn.vdb" >"$tmp/info.json"
"$py" - "$tmp/info.json" <<'PY'
import json, sys
info = json.load(open(sys.argv[1]))
assert info["voxel_size"] == 0.03125, info
assert info["euler_characteristic"] == 2 and info["genus"] == 0, info
assert info["components"] == 1, info
# The unit sphere (4.19) grew a horn: about +15% of volume, reaching up to y = 2.3 (the
# band's box ends about 3 voxels beyond the surface).
sphere = 4 / 3 * 3.141592653589793
assert 1.10 * sphere < info["volume"] < 1.25 * sphere, info["volume"]
assert 2.2 < info["bbox"][1][1] < 2.6, info["bbox"]
# OpenVDB's diagnostics, and how much of their gradient test thin features account for.
assert isinstance(info["openvdb_check"], str), info
assert 0 <= info["eikonal_outliers_on_thin_features"] <= info["eikonal_outliers"], info
assert (info["thin_feature_bbox"] is None) == (info["thin_feature_voxels"] == 0), info
assert (info["eikonal_outliers_elsewhere_bbox"] is None) == (
    info["eikonal_outliers"] == info["eikonal_outliers_on_thin_features"]), info
PY
"$cli" info "$tmp/horn.vdb" | grep -q "OpenVDB's checkLevelSet: " || fail "info: no word of checkLevelSet"
"$cli" mesh "$tmp/horn.vdb" -o "$tmp/horn.obj" 2>/dev/null
grep -q "^f " "$tmp/horn.obj" || fail "mesh wrote no faces"

# --- --half: a float level set to every reader, values rounded within the bound ---------
# (At 0.03 the band's half-width, 0.09, is no 16-bit float: the background is the next one
# up, so OpenVDB's checkLevelSet still reads a band of 3 voxels.)
"$cli" apply "$data/horn.json" -o "$tmp/horn-full.vdb" --voxel-size 0.03 -q
"$cli" info --json "$tmp/horn-full.vdb" >"$tmp/info.json"
"$cli" apply "$data/horn.json" -o "$tmp/horn-half.vdb" --voxel-size 0.03 --half -q
vdb_print -l "$tmp/horn-half.vdb" >"$tmp/print" || fail "vdb_print could not read the --half file"
grep -q "Type: Tree_float_5_4_3" "$tmp/print" || fail "vdb_print: --half not a float tree: $(cat "$tmp/print")"
grep -q "class: level set" "$tmp/print" || fail "vdb_print: --half not a level set"
"$cli" info --json "$tmp/horn-half.vdb" >"$tmp/info-half.json"
"$py" - "$tmp/horn-full.vdb" "$tmp/horn-half.vdb" "$tmp/info.json" "$tmp/info-half.json" \
  "$(dirname "$0")/.." <<'PY'
import json, os, sys, pyopenvdb as vdb
sys.path.insert(0, sys.argv[5])
from half_grid import rounding
worst = rounding(sys.argv[1], sys.argv[2])
half = vdb.read(sys.argv[2], "surface")
i, j = (json.load(open(f)) for f in sys.argv[3:5])
for key in ("volume", "area"):
    assert abs(j[key] - i[key]) <= 1e-4 * abs(i[key]), (key, i[key], j[key])
assert i["openvdb_check"] == "" and j["openvdb_check"] == "", (i, j)
assert 0.09 < half.background < 0.09 * (1 + 1 / 1024), half.background
ratio = os.path.getsize(sys.argv[2]) / os.path.getsize(sys.argv[1])
assert ratio < 0.75, ratio
print(f"--half: {ratio:.3f} of the bytes, largest rounding {worst * 2048:.2f}/2048, "
      f"volume {i['volume']:.7f} -> {j['volume']:.7f}")
PY
# Voxels so small that 16-bit floats lose their relative precision near the surface: refused
# before any work, nothing written.
cat >"$tmp/speck.json" <<'EOF'
{ "sweepers": 1, "grid": { "voxel_size": 0.00005 },
  "start": { "sphere": { "center": [0, 0, 0], "radius": 0.001 } }, "strokes": [] }
EOF
refuses "sweepers-cli: --half: 16-bit floats round a voxel size under 6.1e-05 (5e-05) too coarsely; write at full precision" \
  apply "$tmp/speck.json" -o "$tmp/speck.vdb" --half
[ ! -e "$tmp/speck.vdb" ] || fail "a refused --half left a file"

# --- exported meshes pass the checks of mesh repair tools ------------------------------
# No two vertices at one point, no facet without area or with a repeated corner, every
# edge in exactly two facets that run it opposite ways. (data/mirrored_ears.json once
# exported 16 facets with a repeated corner: crossings exactly on a voxel.)
"$cli" apply "$data/mirrored_ears.json" -o "$tmp/ears.vdb" -q --mesh "$tmp/ears.obj" 2>/dev/null
for obj in "$tmp/horn.obj" "$tmp/ears.obj"; do
  "$py" - "$obj" <<'PY' || fail "$obj fails the mesh checks"
import collections, sys
vs, fs = [], []
for line in open(sys.argv[1]):
    if line.startswith("v "):
        vs.append(tuple(float(t) for t in line.split()[1:4]))
    elif line.startswith("f "):
        fs.append(tuple(int(t.split("/")[0]) - 1 for t in line.split()[1:4]))
assert len(set(vs)) == len(vs), "%d vertices share a point" % (len(vs) - len(set(vs)))
edges = collections.Counter()
for f in fs:
    assert len(set(f)) == 3, "a facet repeats a corner: %s" % (f,)
    a, b, c = (vs[i] for i in f)
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    cross = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
    assert any(cross), "a facet has no area: %s" % (f,)
    for k in range(3):
        edges[(f[k], f[(k + 1) % 3])] += 1
for (i, j), n in edges.items():
    assert n == 1 and edges[(j, i)] == 1, "edge %d-%d: %d one way, %d the other" % (i, j, n, edges[(j, i)])
PY
done

# --- scripts may start from a VDB or a mesh (paths relative to the script) -----------
mkdir "$tmp/starts"
cp "$tmp/sphere.vdb" "$tmp/starts/ball.vdb"
"$cli" mesh "$tmp/sphere.vdb" -o "$tmp/starts/ball.obj" 2>/dev/null
for start in '{"vdb": "ball.vdb"}' '{"mesh": "ball.obj"}'; do
  printf '{"sweepers": 1, "grid": {"voxel_size": 0.025}, "start": %s, "strokes": [{"type": "inflate", "at": [0, 0, 0], "radius": 0.2}]}' "$start" >"$tmp/starts/s.json"
  "$cli" apply "$tmp/starts/s.json" -o "$tmp/starts/out.vdb" -q || fail "start $start"
  "$cli" info --json "$tmp/starts/out.vdb" >"$tmp/starts/info.json"
  "$py" - "$tmp/starts/info.json" <<'PY' || fail "start $start: wrong volume"
import json, math, sys
info = json.load(open(sys.argv[1]))
# a ball of radius 0.5 with a ball of radius 0.2 blown up inside it
expected = 4 / 3 * math.pi * (0.5 ** 3 + 0.2 ** 3)
assert abs(info["volume"] - expected) < 0.03 * expected, (info["volume"], expected)
PY
done

# --- the same script gives identical grids on 1 and 2 threads ------------------------
"$cli" --threads 1 apply "$data/twisted_limb.json" -o "$tmp/t1.vdb" --voxel-size 0.03125 -q
"$cli" --threads 2 apply "$data/twisted_limb.json" -o "$tmp/t2.vdb" --voxel-size 0.03125 -q
# (The files differ in their random UUIDs; compare the grids.)
"$py" - "$tmp/t1.vdb" "$tmp/t2.vdb" <<'PY' || fail "--threads 1 and 2 gave different grids"
import sys, pyopenvdb as vdb
def voxels(path):
    g = vdb.read(path, "surface")
    return g.activeVoxelCount(), sorted((i["min"], i["value"]) for i in g.citerOnValues())
a, b = voxels(sys.argv[1]), voxels(sys.argv[2])
assert a[0] > 1000 and a == b, (a[0], b[0])
PY

# --- failure paths --------------------------------------------------------------------
expect_failure() { # name, expected message part, output file that must not exist, command...
  local name=$1 message=$2 output=$3
  shift 3
  if "$@" >"$tmp/out" 2>"$tmp/err"; then fail "$name: succeeded"; fi
  [ "$(wc -l <"$tmp/err")" -eq 1 ] || { cat "$tmp/err"; fail "$name: not one line on stderr"; }
  grep -q -- "$message" "$tmp/err" || { cat "$tmp/err"; fail "$name: message lacks '$message'"; }
  [ ! -e "$output" ] || fail "$name: left $output behind"
  ls "$tmp" | grep -q "tmp-" && fail "$name: left a temporary file"
  return 0
}
"$py" - "$tmp" <<'PY'
import sys, pyopenvdb as vdb
d = sys.argv[1]
fog = vdb.FloatGrid(0.0); fog.name = "density"; fog.gridClass = vdb.GridClass.FOG_VOLUME
fog.fill((0, 0, 0), (3, 3, 3), 1.0)
vdb.write(d + "/fog.vdb", grids=[fog])
vec = vdb.Vec3SGrid(); vec.name = "velocity"
vec.fill((0, 0, 0), (3, 3, 3), (1, 0, 0))
vdb.write(d + "/vec.vdb", grids=[vec])
PY
printf '{"sweepers": 1, "start": {"vdb": "fog.vdb"}, "strokes": []}' >"$tmp/fogstart.json"
printf '{"sweepers": 1, "strokes": [{"type": "sweep", "tools": []}]}' >"$tmp/bad.json"
printf 'not json' >"$tmp/junk.vdb"
mkdir "$tmp/locked" && chmod 500 "$tmp/locked"

expect_failure "missing script" "missing.json: cannot open" "$tmp/o1.vdb" "$cli" apply "$tmp/missing.json" -o "$tmp/o1.vdb"
expect_failure "bad script" "bad.json: /strokes/0/tools: expected a non-empty array" "$tmp/o2.vdb" "$cli" apply "$tmp/bad.json" -o "$tmp/o2.vdb"
expect_failure "fog start" "no float level set in the file (it holds 'density' (float, fog volume))" "$tmp/o3.vdb" "$cli" apply "$tmp/fogstart.json" -o "$tmp/o3.vdb"
expect_failure "fog info" "no float level set" "/nonexistent" "$cli" info "$tmp/fog.vdb"
expect_failure "vector mesh" "'velocity' (vec3s" "$tmp/o4.obj" "$cli" mesh "$tmp/vec.vdb" -o "$tmp/o4.obj"
expect_failure "corrupt file" "not a readable VDB file" "$tmp/o5.obj" "$cli" mesh "$tmp/junk.vdb" -o "$tmp/o5.obj"
expect_failure "unwritable dir" "cannot write there" "$tmp/nodir/o6.vdb" "$cli" apply "$data/horn.json" -o "$tmp/nodir/o6.vdb"
if [ "$(id -u)" -ne 0 ]; then
  expect_failure "read-only dir" "cannot write there" "$tmp/locked/o7.vdb" "$cli" apply "$data/horn.json" -o "$tmp/locked/o7.vdb"
fi
expect_failure "bad mesh format" "unknown mesh format" "$tmp/o8.vdb" "$cli" apply "$data/horn.json" -o "$tmp/o8.vdb" --mesh "$tmp/o8.xyz"
expect_failure "bad voxel size" "voxel-size" "$tmp/o9.vdb" "$cli" apply "$data/horn.json" -o "$tmp/o9.vdb" --voxel-size -1
expect_failure "impossible size" "voxels" "$tmp/o10.vdb" "$cli" apply "$data/horn.json" -o "$tmp/o10.vdb" --voxel-size 1e-9
# --- Ctrl-C during a long apply: one line, exit 130, no output and no temporary file ----
"$cli" apply "$data/starfish_swirls.json" -o "$tmp/cancelled.vdb" --voxel-size 0.0078125 -q \
  2>"$tmp/err" &
pid=$!
sleep 1
kill -INT "$pid"
code=0
wait "$pid" || code=$?
[ "$code" -eq 130 ] || fail "interrupted apply: exit code $code, not 130"
[ "$(wc -l <"$tmp/err")" -eq 1 ] || { cat "$tmp/err"; fail "interrupted apply: not one line"; }
grep -q "interrupted; nothing was written" "$tmp/err" || { cat "$tmp/err"; fail "interrupted apply: message"; }
[ ! -e "$tmp/cancelled.vdb" ] || fail "interrupted apply: left its output"
ls "$tmp" | grep -q "tmp-" && fail "interrupted apply: left a temporary file"
echo "interrupted apply: $(cat "$tmp/err")"

# --- --up z: the same surface turned so that z is up ((x, y, z) -> (x, -z, y)) -----------
"$cli" mesh "$tmp/sphere.vdb" -o "$tmp/y.obj" 2>/dev/null
"$cli" mesh "$tmp/sphere.vdb" -o "$tmp/z.obj" --up z 2>/dev/null
"$py" - "$tmp/y.obj" "$tmp/z.obj" <<'PY'
import sys
def lines(path, tag):
    return [list(map(float, l.split()[1:4])) for l in open(path) if l.startswith(tag + " ")]
for tag in ("v", "vn"):
    a, b = lines(sys.argv[1], tag), lines(sys.argv[2], tag)
    assert len(a) == len(b) > 0, (tag, len(a), len(b))
    for (x, y, z), (u, v, w) in zip(a, b):
        assert abs(u - x) < 1e-6 and abs(v + z) < 1e-6 and abs(w - y) < 1e-6, (tag, x, y, z, u, v, w)
faces = lambda p: [l for l in open(p) if l.startswith("f ")]
assert faces(sys.argv[1]) == faces(sys.argv[2]), "the triangles changed"
PY
if "$cli" mesh "$tmp/sphere.vdb" -o "$tmp/x.obj" --up x 2>/dev/null; then fail "--up x accepted"; fi

# --- a flow: Enright's sphere carried to t = 3 comes back; bad flows are refused -------
"$cli" apply "$data/flows/enright.json" -o "$tmp/enright.vdb" --voxel-size 0.03125 2>"$tmp/log"
grep -q "1 segments" "$tmp/log" || fail "Enright to t = 3: $(cat "$tmp/log")"
"$cli" new -o "$tmp/enright_start.vdb" --voxel-size 0.03125 --radius 0.15 --center 0.35 0.35 0.35
"$py" - "$tmp/enright_start.vdb" "$tmp/enright.vdb" <<'PY'
import sys, pyopenvdb as vdb
import numpy as np
def inside(path):
    g = vdb.read(path, "surface")
    lo, hi = g.evalActiveVoxelBoundingBox()
    a = np.empty([hi[k] - lo[k] + 1 for k in range(3)], dtype=np.float32)
    g.copyToArray(a, ijk=lo)
    return int((a < 0).sum())
before, after = inside(sys.argv[1]), inside(sys.argv[2])
print(f"Enright at 1/32 to t = 3: {before} voxels inside before, {after} after")
assert abs(after - before) <= 0.02 * before, (before, after)
PY
sed 's/"from": 0, "to": 3/"from": 3, "to": 0/' "$data/flows/enright.json" >"$tmp/backwards.json"
refuses "sweepers-cli: $tmp/backwards.json: /strokes/0/to: a flow runs forward in time: to (0) must come after from (3)" \
  apply "$tmp/backwards.json" -o "$tmp/no.vdb"
sed 's/"to": 3 }/"to": 3, "segments": 0 }/' "$data/flows/enright.json" >"$tmp/zero.json"
refuses "sweepers-cli: $tmp/zero.json: /strokes/0/segments: expected a whole number from 1 to 4096, got 0" \
  apply "$tmp/zero.json" -o "$tmp/no.vdb"
[ ! -e "$tmp/no.vdb" ] || fail "a refused flow wrote its output"

echo "engine cli: ok"

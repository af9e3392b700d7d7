#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Files we did not write cannot take sweepers-cli down: broken meshes (indices out of
# range or negative, non-finite or enormous coordinates, a header announcing 2^31
# vertices, an open surface), level sets with non-finite values or no surface, files of
# several grids (--grid picks one; an unusable level set hides no usable one), scripts with
# duplicate keys or impossible sizes each get one line that says what is wrong, a non-zero
# exit and no output; then a fixed corpus of damaged VDB, PLY, OBJ, STL and JSON files must
# each end in success or such a refusal, within a time bound, never a crash (OpenVDB's
# reader, which crashes on some of them, runs in a child process).
. "$(dirname "$0")/common.sh" "$@"
here=$(cd "$(dirname "$0")" && pwd)
cd "$tmp"

# Runs the CLI expecting a refusal whose one line contains `message`, and no output file.
rejects() {
  local message=$1
  shift
  local rc=0
  timeout 60 "$cli" "$@" -o out.vdb >/dev/null 2>err || rc=$?
  [ "$rc" = 1 ] || fail "$*: exit $rc, expected 1 ($(cat err))"
  [ "$(wc -l <err)" = 1 ] || fail "$*: expected one line, got: $(cat err)"
  grep -qF "$message" err || fail "$*: expected '$message', got: $(cat err)"
  [ ! -e out.vdb ] || fail "$*: wrote out.vdb"
}
script_for() { # a script starting from mesh file $1 at voxel size $2
  printf '{"sweepers": 1, "grid": {"voxel_size": %s, "half_width": 3}, "start": {"mesh": "%s"}, "strokes": []}\n' "$2" "$1" >"$1.json"
}

# --- hand-made broken meshes -----------------------------------------------------------------
"$py" - <<'PY'
def ply(name, verts, faces, count=None):
    with open(name, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
                "property float z\nelement face %d\nproperty list uchar int vertex_indices\n"
                "end_header\n" % (len(verts) if count is None else count, len(faces)))
        f.writelines("%s %s %s\n" % v for v in verts)
        f.writelines("3 %d %d %d\n" % t for t in faces)
V = [(-0.5, -0.5, -0.5), (0.5, -0.5, -0.5), (0, 0.5, -0.5), (0, 0, 0.5)]
F = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)]
ply("good.ply", V, F)
ply("past_end.ply", V, F[:3] + [(2, 0, 99)])
ply("negative.ply", V, F[:3] + [(2, 0, -5)])
ply("infinite.ply", V[:3] + [("inf", "0", "0.5")], F)
ply("nan.ply", V[:3] + [("nan", "0", "0.5")], F)
ply("enormous.ply", [(x * 1e3, y * 1e3, z * 1e3) for x, y, z in V], F)
ply("announces.ply", V, F, count=2**31)
ply("open.ply", V, F[:3])
# Binary: a face count that the bytes after the header cannot hold.
import struct
with open("announces_binary.ply", "wb") as f:
    f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
            b"property float y\nproperty float z\nelement face 100000000\n"
            b"property list uchar int vertex_indices\nend_header\n")
    for v in V:
        f.write(struct.pack("<3f", *v))
    for t in F:
        f.write(struct.pack("<B3i", 3, *t))
PY
for f in good past_end negative infinite nan enormous announces announces_binary open; do
  script_for $f.ply 0.05
done
"$cli" apply good.ply.json -q -o good.vdb || fail "the good tetrahedron was refused"
rejects "face 3 refers to vertex 99, but the mesh has 4 vertices" apply past_end.ply.json -q
rejects "face 3 refers to vertex -5, but the mesh has 4 vertices" apply negative.ply.json -q
rejects "1 vertices have coordinates that are not finite numbers" apply infinite.ply.json -q
rejects "1 vertices have coordinates that are not finite numbers" apply nan.ply.json -q
rejects "the start shape needs about" apply enormous.ply.json -q
grep -q "over its limit of .* available); use a coarser voxel size, --max-memory or --force" err ||
  fail "the memory refusal does not say what to do: $(cat err)"
rejects "announces.ply: the header announces 2147483648 vertex elements, more than the file's 80 bytes of data can hold (a damaged header?)" \
  apply announces.ply.json -q
rejects "announces_binary.ply: the header announces 100000000 face elements, more than the file's 100 bytes of data can hold (a damaged header?)" \
  apply announces_binary.ply.json -q
rejects "the mesh is not closed (3 edges border a single triangle), so it has no inside" \
  apply open.ply.json -q

# --- level sets: non-finite values, no surface --------------------------------------------
"$cli" new -o sphere.vdb --voxel-size 0.1 --radius 0.5
"$py" - <<'PY'
import pyopenvdb as vdb
g = vdb.read("sphere.vdb", "surface")
acc, n = g.getAccessor(), 0
for it in g.iterOnValues():
    if it.count == 1 and n < 5:
        acc.setValueOnly(it.min, float("nan"))
        n += 1
vdb.write("nan.vdb", grids=[g])
e = vdb.FloatGrid(0.3)
e.name, e.gridClass = "surface", vdb.GridClass.LEVEL_SET
e.transform = vdb.createLinearTransform(voxelSize=0.1)
vdb.write("empty.vdb", grids=[e])
PY
rc=0
"$cli" info nan.vdb 2>err >/dev/null || rc=$?
[ "$rc" = 1 ] && grep -qF "holds 5 values that are not finite numbers" err ||
  fail "a grid with NaN values: exit $rc, $(cat err)"
"$cli" info empty.vdb | grep -q "bbox empty (no active voxels)" || fail "info on an empty level set"
rc=0
"$cli" mesh empty.vdb -o empty.ply 2>err || rc=$?
[ "$rc" = 1 ] && grep -qF "nothing to write: the surface is empty" err && [ ! -e empty.ply ] ||
  fail "mesh of an empty level set: exit $rc, $(cat err)"

# --- several grids in one file: --grid picks one, a thin level set hides no good one -------
"$cli" new -o ball.vdb --radius 0.5 --voxel-size 0.05 2>/dev/null
"$cli" new -o big.vdb --radius 0.8 --voxel-size 0.05 2>/dev/null
"$py" - <<'PY'
import pyopenvdb as vdb
ball = vdb.read("ball.vdb", "surface"); ball.name = "ball"
big = vdb.read("big.vdb", "surface"); big.name = "big"
thin = vdb.FloatGrid(0.05)  # a band of one voxel: not usable
thin.name, thin.gridClass = "a_thin", vdb.GridClass.LEVEL_SET
thin.transform = vdb.createLinearTransform(voxelSize=0.05)
fog = vdb.FloatGrid(0.0)
fog.name, fog.gridClass = "density", vdb.GridClass.FOG_VOLUME
vdb.write("multi.vdb", grids=[thin, fog, ball, big])
PY
"$cli" info multi.vdb >info.txt || fail "info on a file of four grids"
grep -qF "multi.vdb, grid 'ball'" info.txt || fail "info did not take the first usable level set: $(cat info.txt)"
grep -qF "the file holds 4 grids: 'a_thin' (float, level set), 'ball' (float, level set), 'big' (float, level set), 'density' (float, fog volume)" info.txt ||
  fail "info did not list the grids: $(cat info.txt)"
"$cli" info multi.vdb --grid big | grep -qF "multi.vdb, grid 'big'" || fail "info --grid big"
"$cli" info multi.vdb --grid big --json | grep -qF '"grid": "big"' || fail "info --grid big --json"
"$cli" mesh multi.vdb -o ball.obj 2>err || fail "mesh of a file of four grids: $(cat err)"
grep -qF "multi.vdb holds 3 level sets; using 'ball' (choose with --grid NAME)" err ||
  fail "mesh did not say which grid it took: $(cat err)"
"$cli" mesh multi.vdb --grid big -o big.obj 2>err && ! grep -q "level sets; using" err ||
  fail "mesh --grid big: $(cat err)"
"$cli" mesh big.vdb -o big_alone.obj 2>/dev/null
cmp -s big.obj big_alone.obj || fail "mesh --grid big differs from the mesh of the same grid alone"
for case in "a_thin|grid 'a_thin' has a band of 1 voxels; Sweepers needs at least 2" \
  "density|grid 'density' (float, fog volume) is not a float level set" \
  "nope|no grid named 'nope' (it holds 'a_thin' (float, level set), 'ball'"; do
  rc=0
  "$cli" info multi.vdb --grid "${case%%|*}" 2>err >/dev/null || rc=$?
  [ "$rc" = 1 ] && [ "$(wc -l <err)" = 1 ] && grep -qF "${case#*|}" err ||
    fail "info --grid ${case%%|*}: exit $rc, $(cat err)"
done
# A script starts from a grid of such a file by name; a VDB start keeps its own grid, so a
# script or a command line asking for another voxel size or band is refused, not ignored.
printf '{"sweepers": 1, "grid": {"voxel_size": 0.05}, "start": {"vdb": "multi.vdb", "grid": "big"}, "strokes": []}' >named.json
"$cli" apply named.json -o named.vdb -q || fail "apply from a named grid of a file"
"$cli" mesh named.vdb -o named.obj 2>/dev/null
cmp -s named.obj big_alone.obj || fail "the start grid named 'big' is not the sphere of radius 0.8"
printf '{"sweepers": 1, "grid": {"voxel_size": 0.02}, "start": {"vdb": "multi.vdb"}, "strokes": []}' >h.json
printf '{"sweepers": 1, "grid": {"half_width": 4}, "start": {"vdb": "multi.vdb"}, "strokes": []}' >hw.json
printf '{"sweepers": 1, "start": {"vdb": "multi.vdb"}, "strokes": []}' >plain.json
rejects "multi.vdb: its voxel size 0.05 differs from the script's /grid/voxel_size 0.02 (a VDB start keeps its own grid: give 0.05 or leave the setting out)" apply h.json
rejects "multi.vdb: its band half-width 3 differs from the script's /grid/half_width 4" apply hw.json
rejects "multi.vdb: its voxel size 0.05 differs from --voxel-size 0.1" apply plain.json --voxel-size 0.1
"$cli" apply plain.json -o plain.vdb -q || fail "apply from the first usable grid of a file"

# --- scripts: duplicate keys, sizes check refuses as apply does ---------------------------
printf '{"sweepers": 1, "grid": {"voxel_size": 0.05, "voxel_size": 0.1, "half_width": 3}, "start": {"sphere": {"center": [0, 0, 0], "radius": 1}}, "strokes": []}' >dup.json
for cmd in check apply; do
  rc=0
  "$cli" $cmd dup.json $([ $cmd = apply ] && echo "-o out.vdb") 2>err >/dev/null || rc=$?
  [ "$rc" = 1 ] && grep -qF "/grid/voxel_size appears twice in the same object" err ||
    fail "$cmd with a duplicate key: exit $rc, $(cat err)"
done
for size in 1e308 0.00001; do
  printf '{"sweepers": 1, "grid": {"voxel_size": %s, "half_width": 3}, "start": {"sphere": {"center": [0, 0, 0], "radius": 1}}, "strokes": []}' $size >size.json
  rc=0
  "$cli" check size.json 2>check.err >/dev/null || rc=$?
  "$cli" apply size.json -o out.vdb 2>apply.err >/dev/null && fail "apply took voxel size $size"
  # The same refusal, but for the memory free at each moment (other work runs meanwhile).
  masked() { sed -E 's/[0-9.]+ [KMGT]?B (available|\()/N \1/g' "$1"; }
  [ "$rc" = 1 ] && [ "$(masked check.err)" = "$(masked apply.err)" ] ||
    fail "voxel size $size: check says '$(cat check.err)', apply says '$(cat apply.err)'"
  [ "$(wc -c <check.err)" -lt 240 ] || fail "a long refusal: $(cat check.err)"
done

# --- a fixed corpus of damaged files ---------------------------------------------------------
"$cli" new -o small.vdb --voxel-size 0.1 --radius 0.5
for ext in ply obj stl; do "$cli" mesh small.vdb -o "small.$ext" 2>/dev/null; done
# 225 cases: a mesh case, whose script imports it, costs the most under the sanitizers, so
# meshes get the fewest.
for ext in ply obj stl; do "$py" "$here/mutate.py" "small.$ext" corpus 25 7; done
"$py" "$here/mutate.py" "$data/horn.json" corpus 60 7
"$py" "$here/mutate.py" small.vdb corpus 90 7
# Builtins only around each run (a few more processes per case, times hundreds of cases,
# would add up). A refusal
# is one line that says something in words, never just an exception's name (bytes, not
# characters: a message may quote the damaged file).
LC_ALL=C
nl=$'\n'
one_line="^sweepers-cli: [^$nl]*[a-z] [a-z][^$nl]*$nl?\$"
declare -A outcome
for f in corpus/*; do
  ext=${f##*.}
  case $ext in
  json) args=(check "$f") ;;
  vdb) args=(mesh "$f" -o corpus.ply) ;;
  *) # a script beside the mesh, which it names
    printf '{"sweepers": 1, "grid": {"voxel_size": 0.05, "half_width": 3}, "start": {"mesh": "%s"}, "strokes": []}\n' "${f##*/}" >"$f.json"
    args=(apply "$f.json" -q -o corpus.vdb) ;;
  esac
  rc=0
  timeout 30 "$cli" "${args[@]}" >/dev/null 2>err || rc=$?
  message=
  IFS= read -r -d '' message <err || true
  if [ "$rc" = 0 ]; then
    outcome[$ext.read]=$((${outcome[$ext.read]:-0} + 1))
  elif [ "$rc" = 1 ] && [[ $message =~ $one_line && ! $message =~ bad_alloc ]]; then
    outcome[$ext.refused]=$((${outcome[$ext.refused]:-0} + 1))
  else
    fail "$f: exit $rc ($( [ "$rc" -gt 128 ] && echo "signal $((rc - 128))"; [ "$rc" = 124 ] && echo "timed out")) ${message:0:300}"
  fi
done
for ext in vdb ply obj stl json; do
  echo "damaged $ext: ${outcome[$ext.read]:-0} read, ${outcome[$ext.refused]:-0} refused in one line"
done
echo "loaders: every broken file refused cleanly"

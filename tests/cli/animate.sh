#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# sweepers-cli animate: a script played as a film, one VDB per frame (and a mesh and a fog
# volume when asked), read back by vdb_print and python3-openvdb; the ends of the film
# against the start and `apply`; resuming; Ctrl-C; and every refusal with its message.
. "$(dirname "$0")/common.sh" "$@"
here=$(cd "$(dirname "$0")" && pwd)
h=0.03125 # coarser than the script's 1/64: the same film, four times faster
film="$data/animation/horn_film.json"

# --- the horn as a 2-second film at 6 fps: 13 frames ---------------------------------------
"$cli" animate "$film" -o "$tmp/f/horn_####.vdb" --fps 6 --voxel-size $h --fog \
  --mesh "$tmp/m/horn_##.ply" -q
[ "$(ls "$tmp/f" | wc -l)" = 13 ] || fail "expected 13 frames: $(ls "$tmp/f")"
[ "$(ls "$tmp/m" | wc -l)" = 13 ] || fail "expected 13 meshes: $(ls "$tmp/m")"
[ -f "$tmp/f/horn_0013.vdb" ] && [ -f "$tmp/m/horn_13.ply" ] || fail "numbering: $(ls "$tmp/f" "$tmp/m")"

# Frame 1 is the start, the last frame what apply gives, voxel for voxel.
"$cli" new -o "$tmp/start.vdb" --voxel-size $h --radius 1
"$py" "$here/../app/same_grid.py" "$tmp/f/horn_0001.vdb" "$tmp/start.vdb"
"$cli" apply "$film" -o "$tmp/applied.vdb" --voxel-size $h -q
"$py" "$here/../app/same_grid.py" "$tmp/f/horn_0013.vdb" "$tmp/applied.vdb"

# An independent reader sees both grids with their classes and the frame's metadata.
vdb_print -l "$tmp/f/horn_0007.vdb" >"$tmp/print"
grep -q "^Name: surface" "$tmp/print" && grep -q "^Name: density" "$tmp/print" &&
  grep -q "class: level set" "$tmp/print" && grep -q "class: fog volume" "$tmp/print" &&
  grep -q "frame: 7" "$tmp/print" || fail "vdb_print: $(cat "$tmp/print")"

# Every frame: names, classes, metadata (time = (frame - 1) / fps, a digest of what the
# frame is made of: one per frame, as each shows the horn at another time), the
# volume growing with the horn, and a fog volume: 0 outside, 1 deep inside, in between
# only across the inside of the band.
"$py" - "$tmp/f" <<'PY'
import glob, sys
import numpy as np
import pyopenvdb as vdb
files = sorted(glob.glob(f"{sys.argv[1]}/horn_*.vdb"))
digests, volumes = set(), []
for n, path in enumerate(files, start=1):
    grids, meta = vdb.readAll(path)
    by_name = {g.name: g for g in grids}
    assert set(by_name) == {"surface", "density"}, (path, by_name)
    s, d = by_name["surface"], by_name["density"]
    assert s.gridClass == vdb.GridClass.LEVEL_SET and d.gridClass == vdb.GridClass.FOG_VOLUME
    for g in (s, d):
        assert g["frame"] == n and abs(g["time"] - (n - 1) / 6) < 1e-12 and g["fps"] == 6, g.metadata
    digests.add(s["script"])
    h = s.transform.voxelSize()[0]
    assert abs(h - 1 / 32) < 1e-12, h
    lo, hi = s.evalActiveVoxelBoundingBox()
    a = np.empty([hi[k] - lo[k] + 1 for k in range(3)], dtype=np.float32)
    s.copyToArray(a, ijk=lo)
    volumes.append(int((a < 0).sum()))
    if n == 7:
        acc, fog = s.getConstAccessor(), d.getConstAccessor()
        assert fog.getValue((0, 0, 0)) == 1.0 and d.background == 0.0
        assert fog.getValue((0, 200, 0)) == 0.0 and fog.getValue((60, 0, 0)) == 0.0
        band = s.background
        for ijk in [(i, 0, 0) for i in range(20, 40)]:
            phi, rho = acc.getValue(ijk), fog.getValue(ijk)
            expected = 0.0 if phi >= 0 else min(1.0, -phi / band)
            assert abs(rho - expected) < 1e-5, (ijk, phi, rho)
assert len(digests) == len(files), digests
# The voxels inside: the horn is pulled out frame after frame, none a still.
assert all(b > a for a, b in zip(volumes, volumes[1:])), volumes
print(f"{len(files)} frames read back: level set and fog volume, frame, time, fps, script")
PY

# The fog volume beside it changes nothing in the level set.
"$cli" animate "$film" -o "$tmp/plain/horn_####.vdb" --fps 6 --voxel-size $h --frames 7 -q
[ "$(ls "$tmp/plain")" = horn_0007.vdb ] || fail "--frames 7 wrote $(ls "$tmp/plain")"
"$py" "$here/../app/same_grid.py" "$tmp/plain/horn_0007.vdb" "$tmp/f/horn_0007.vdb"

# --- keyed strokes: a grab that comes back gives back the start; a bulge slides -----------
"$cli" animate "$data/animation/keyframed_grab.json" -o "$tmp/g/grab_#.vdb" --fps 4 \
  --voxel-size $h -q
[ "$(ls "$tmp/g" | wc -l)" = 9 ] || fail "the 2-second grab at 4 fps: $(ls "$tmp/g")"
"$py" "$here/../app/same_grid.py" "$tmp/g/grab_1.vdb" "$tmp/start.vdb"
"$py" "$here/../app/same_grid.py" "$tmp/g/grab_9.vdb" "$tmp/start.vdb"
volume() { "$cli" info --json "$1" | "$py" -c 'import json, sys; print(json.load(sys.stdin)["volume"])'; }
"$py" -c 'import sys; a, b = map(float, sys.argv[1:]); assert b > a + 0.1, (a, b)' \
  "$(volume "$tmp/start.vdb")" "$(volume "$tmp/g/grab_5.vdb")" || fail "the grab pulled nothing"
"$cli" animate "$data/animation/sliding_bulge.json" -o "$tmp/s/bulge_#.vdb" --fps 2 \
  --voxel-size $h -q
[ "$(ls "$tmp/s" | wc -l)" = 5 ] || fail "the 2-second slide at 2 fps: $(ls "$tmp/s")"
echo "keyed strokes: the grab comes back to the start, the bulge slides in 5 frames"

# --- OpenVDB's checkLevelSet on every frame of both films: the only complaint it may make
# is its gradient test's, and its refusals that `info` does not put on a feature the grid
# does not resolve are at most as many as measured when this test was written (none is the
# goal).
peer_check() { # the frames, the most unexplained refusals in all of them
  mkdir -p "$tmp/peer" && rm -f "$tmp/peer/"*
  for f in $1; do "$cli" info --json "$f" >"$tmp/peer/$(basename "$f").json"; done
  "$py" - "$2" "$tmp/peer" <<'PY'
import glob, json, sys
most, total, seen = int(sys.argv[1]), 0, []
for path in sorted(glob.glob(sys.argv[2] + "/*.json")):
    info = json.load(open(path))
    check, n = info["openvdb_check"], info["eikonal_outliers"]
    assert check == "" if n == 0 else "outside the range of NormGrad" in check, (path, check)
    total += n - info["eikonal_outliers_on_thin_features"]
    seen.append(n)
print(f"checkLevelSet on {len(seen)} frames: refused per frame {seen}, {total} not on thin features")
assert total <= most, (total, most)
PY
}
peer_check "$tmp/f/horn_*.vdb" 0 || fail "checkLevelSet on the horn film"
peer_check "$tmp/g/grab_*.vdb" 0 || fail "checkLevelSet on the keyed grab"

# --- an edited key: refused without --force; with it, only the frames the key's spline
# reaches are made again (key 1, at 0.5 s, shapes the spline from 0 to 1.5 s: frames 2 to 6
# at 4 fps); the others are kept, untouched ------------------------------------------------
sed 's/{ "time": 0.5, "t": \[1.3, 0.3, 0\] }/{ "time": 0.5, "t": [1.3, 0.45, 0] }/' \
  "$data/animation/keyframed_grab.json" >"$tmp/edited_grab.json"
! cmp -s "$tmp/edited_grab.json" "$data/animation/keyframed_grab.json" || fail "the key was not edited"
cp -a "$tmp/g" "$tmp/g_before"
grab_stamps() { for n in $(seq 9); do stat -c "$n %Y.%y" "$tmp/g/grab_$n.vdb"; done; }
before=$(grab_stamps)
refuses "sweepers-cli: $tmp/g/grab_2.vdb: not frame 2 of this film (another script, timing, voxel size, fog or precision); --force overwrites it" \
  animate "$tmp/edited_grab.json" -o "$tmp/g/grab_#.vdb" --fps 4 --voxel-size $h
"$cli" animate "$tmp/edited_grab.json" -o "$tmp/g/grab_#.vdb" --fps 4 --voxel-size $h \
  --force 2>"$tmp/err"
grep -q "wrote frames 1-9 of 9 (2 s at 4 fps) to $tmp/g/grab_#.vdb, 4 kept from before" \
  "$tmp/err" || fail "edited key: $(cat "$tmp/err")"
after=$(grab_stamps)
rewritten=$({ diff <(echo "$before") <(echo "$after") || true; } | grep '^>' | cut -d' ' -f2 |
  tr '\n' ' ')
[ "$rewritten" = "2 3 4 5 6 " ] || fail "edited key 1: frames rewritten: $rewritten"
for n in 3 4 6; do
  if "$py" "$here/../app/same_grid.py" "$tmp/g/grab_$n.vdb" "$tmp/g_before/grab_$n.vdb" \
    >/dev/null 2>&1; then fail "frame $n did not change with its key"; fi
done
echo "edited key 1: frames $rewritten made again, frames 1 and 7-9 kept"

# --- resuming: the frames of the same film are kept, a missing one is made again -----------
stamps() { stat -c '%n %Y.%y' "$tmp/f"/*.vdb | grep -v horn_0004; }
before=$(stamps)
mv "$tmp/f/horn_0004.vdb" "$tmp/frame4.vdb"
"$cli" animate "$film" -o "$tmp/f/horn_####.vdb" --fps 6 --voxel-size $h --fog \
  --mesh "$tmp/m/horn_##.ply" 2>"$tmp/err"
grep -q "wrote frames 1-13 of 13 (2 s at 6 fps) to $tmp/f/horn_####.vdb, 12 kept from before" \
  "$tmp/err" || fail "resume: $(cat "$tmp/err")"
[ "$(stamps)" = "$before" ] || fail "a kept frame was written again"
"$py" "$here/../app/same_grid.py" "$tmp/f/horn_0004.vdb" "$tmp/frame4.vdb"
echo "resumed: 12 frames kept, frame 4 made again"

# --- --half: frames with 16-bit float values, within their bound of the exact frames; a
# film at the other precision is another film ----------------------------------------------
"$cli" animate "$film" -o "$tmp/hf/horn_####.vdb" --fps 6 --frames 1-3 --voxel-size $h --fog \
  --half -q
"$py" "$here/../half_grid.py" "$tmp/f/horn_0003.vdb" "$tmp/hf/horn_0003.vdb"
[ "$(vdb_print -l "$tmp/hf/horn_0003.vdb" | grep -c "frame: 3")" = 2 ] ||
  fail "--half frame 3: $(vdb_print -l "$tmp/hf/horn_0003.vdb")"
refuses "sweepers-cli: $tmp/hf/horn_0001.vdb: not frame 1 of this film (another script, timing, voxel size, fog or precision); --force overwrites it" \
  animate "$film" -o "$tmp/hf/horn_####.vdb" --fps 6 --frames 1-3 --voxel-size $h --fog
echo "--half: frames 1-3 at 16-bit floats, within 1/2048; at full precision another film"

# --- Ctrl-C: the frames written are whole and kept ---------------------------------------
stopped INT "$tmp/err" '[ "$(ls "$tmp/c" 2>/dev/null | grep -c "vdb$")" -ge 3 ]' \
  animate "$film" -o "$tmp/c/horn_####.vdb" --fps 6 --voxel-size $h -q
[ "$rc" = 130 ] || fail "animate stopped by SIGINT exited $rc"
grep -qx "sweepers-cli: interrupted; the frames written are kept (the same command resumes the film)" \
  "$tmp/err" || fail "SIGINT: $(cat "$tmp/err")"
if ls "$tmp/c" | grep -q "tmp-"; then fail "temporary files left: $(ls "$tmp/c")"; fi
for f in "$tmp/c"/*.vdb; do "$cli" info "$f" >/dev/null || fail "$f is not whole"; done
echo "stopped by SIGINT: exit 130, $(ls "$tmp/c" | wc -l) whole frames kept"

# --- refusals: one line, nothing written -------------------------------------------------
refuses "sweepers-cli: $tmp/f/horn_0001.vdb: not frame 1 of this film (another script, timing, voxel size, fog or precision); --force overwrites it" \
  animate "$data/horn.json" -o "$tmp/f/horn_####.vdb" --fps 6 --voxel-size $h
refuses "sweepers-cli: $tmp/f/horn_0001.vdb: not frame 1 of this film (another script, timing, voxel size, fog or precision); --force overwrites it" \
  animate "$film" -o "$tmp/f/horn_####.vdb" --fps 24 --voxel-size $h
refuses "sweepers-cli: $tmp/f/horn_0001.vdb: not frame 1 of this film (another script, timing, voxel size, fog or precision); --force overwrites it" \
  animate "$film" -o "$tmp/f/horn_####.vdb" --fps 6 --voxel-size 0.0625
refuses "sweepers-cli: $tmp/bad/horn.vdb: a frame pattern needs a run of '#' for the frame number (for example frames/shape_####.vdb)" \
  animate "$film" -o "$tmp/bad/horn.vdb"
refuses "sweepers-cli: $tmp/bad/h_##_##.vdb: a frame pattern holds one run of '#', not two" \
  animate "$film" -o "$tmp/bad/h_##_##.vdb"
refuses "sweepers-cli: --frames: 20-30 is not within the film's frames 1-13" \
  animate "$film" -o "$tmp/bad/h_#.vdb" --fps 6 --frames 20-30
refuses "sweepers-cli: --frames: 'ten' is not a frame range such as 1-13" \
  animate "$film" -o "$tmp/bad/h_#.vdb" --fps 6 --frames ten
touch "$tmp/file"
refuses "sweepers-cli: $tmp/file/h_01.vdb: cannot create its directory (Not a directory)" \
  animate "$film" -o "$tmp/file/h_##.vdb"
sed 's/"duration": 1.2/"duration": -1/' "$film" >"$tmp/negative.json"
refuses "sweepers-cli: $tmp/negative.json: /strokes/0/duration: must be positive (got -1)" \
  animate "$tmp/negative.json" -o "$tmp/bad/h_#.vdb"
sed 's/"time": 1.5/"time": 0.4/' "$data/animation/keyframed_grab.json" >"$tmp/unordered.json"
refuses "sweepers-cli: $tmp/unordered.json: /strokes/0/keys/3/time: keys must come in increasing time (this one is at 0.4, the one before at 1)" \
  animate "$tmp/unordered.json" -o "$tmp/bad/h_#.vdb"
[ ! -e "$tmp/bad" ] || fail "a refused film left $(ls -R "$tmp/bad")"
echo "animate: all checks passed"

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The modeler's timeline in a real window (run under xvfb-run with Mesa): a replayed drag,
# its history opened as a film (V) and stepped with the keys to its middle frame, which is
# saved and measured; the film recorded as PNGs; a directory for them that cannot be made.
. "$(dirname "$0")/common.sh" "$@"
run() { ASAN_OPTIONS=$app_asan "$app" --size 640x480 --hide-ui "$@"; }

# --- the drag of drag_a.json (4 path segments: a film of 4 x 0.25 s at 24 fps, 25 frames),
# then V opens the film at frame 1; "." 13 times and "," once step to frame 13, the middle
# (the step back plays the film again from the start shape)
"$py" - "$here/drag_a.json" "$tmp/scrub.json" <<'PY'
import json, sys
events = json.load(open(sys.argv[1]))["events"]
frame = events[-1]["frame"] + 2
keys = ["v"] + ["."] * 13 + [","]
for k in keys:
    events.append({"frame": frame, "type": "key", "key": k})
    frame += 1
json.dump({"events": events}, open(sys.argv[2], "w"))
PY
run --voxel-size 0.03125 --replay-input "$tmp/scrub.json" --save "$tmp/end.vdb" \
    --save-script "$tmp/drag.json" --save-frame "$tmp/middle.vdb"
"$cli" new -o "$tmp/start.vdb" --voxel-size 0.03125 --radius 1
for g in start middle end; do "$cli" info --json "$tmp/$g.vdb" >"$tmp/$g.info"; done
"$py" - "$tmp/drag.json" "$tmp/start.info" "$tmp/middle.info" "$tmp/end.info" <<'PY'
import json, sys
path = json.load(open(sys.argv[1]))["strokes"][0]["tools"][0]["path"]
assert len(path) == 5, f"{len(path) - 1} segments, not 4: frame 13 is not the middle"
start, middle, end = (json.load(open(p))["volume"] for p in sys.argv[2:5])
print(f"volume: start {start:.5f}, frame 13 of 25 {middle:.5f}, end {end:.5f}")
assert end > start + 0.01, "the drag did not pull the surface out"
# Half the drag: well inside, not at either end.
assert start + 0.1 * (end - start) < middle < end - 0.1 * (end - start), "not in between"
PY

# --- the film of the recorded script as PNGs: 25 frames, the first and the last differ; the
# last frame shown is the document the drag made ---------------------------------------
run "$tmp/drag.json" --record-frames "$tmp/frames" --save-frame "$tmp/last.vdb" 2>"$tmp/err"
cat "$tmp/err"
grep -qx "sweepers: wrote 25 frames to $tmp/frames" "$tmp/err" || fail "no report of 25 frames"
[ "$(ls "$tmp/frames")" = "$(printf 'frame_%04d.png\n' $(seq 25))" ] ||
  fail "frames written: $(ls "$tmp/frames" | tr '\n' ' ')"
"$py" "$here/check_image.py" changed "$tmp/frames/frame_0001.png" "$tmp/frames/frame_0025.png"
"$py" "$here/same_grid.py" "$tmp/end.vdb" "$tmp/last.vdb"

# --- a place where the directory cannot be made: one line, non-zero exit, nothing written
touch "$tmp/file"
if run "$tmp/drag.json" --record-frames "$tmp/file/frames" 2>"$tmp/err"; then
  fail "--record-frames under a file succeeded"
fi
cat "$tmp/err"
[ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "^sweepers: $tmp/file/frames: cannot make the directory" \
  "$tmp/err" || fail "no clear message for a directory that cannot be made"
echo "all timeline checks passed"

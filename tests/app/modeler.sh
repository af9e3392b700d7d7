#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The modeler in a real window (run under xvfb-run with Mesa): screenshots read back as
# pixels, replayed mouse and keyboard input, undo / redo, the recorded script replayed by
# sweepers-cli, and bad files opened in the window.
. "$(dirname "$0")/common.sh" "$@"
headless=$3
# New spheres at voxel size 1/32: the window, the input and the files are what is tested
# here, and the engine at finer sizes elsewhere.
run() { ASAN_OPTIONS=$app_asan "$app" --size 640x480 --voxel-size 0.03125 "$@"; }
echo '{"events": []}' >"$tmp/none.json"
version=$(run --version)
[ "$version" = "sweepers $("$cli" --version | cut -d' ' -f2)" ] || fail "sweepers --version: '$version'"
rc=0
run --no-such-option 2>/dev/null || rc=$?
[ "$rc" = 2 ] || fail "a usage error exited $rc, not 2 (docs/cli.md's codes hold for the modeler too)"

# --- the default scene: a sphere in the middle -----------------------------------------
run --hide-ui --screenshot "$tmp/default.png" --replay-input "$tmp/none.json" --save "$tmp/default.vdb"
"$py" "$here/check_image.py" centred "$tmp/default.png"
# --half: what Save writes holds 16-bit floats, the same sphere within their rounding.
run --hide-ui --replay-input "$tmp/none.json" --half --save "$tmp/default-half.vdb"
"$py" "$here/../half_grid.py" "$tmp/default.vdb" "$tmp/default-half.vdb"

# --- the looks: the lit clay and three matcaps, on the same sphere ----------------------
for look in clay glossy red-wax normals; do
  run --hide-ui --look "$look" --screenshot "$tmp/look-$look.png" --replay-input "$tmp/none.json"
done
"$py" "$here/check_image.py" looks "$tmp/look-clay.png" "$tmp/look-glossy.png" \
  "$tmp/look-red-wax.png" "$tmp/look-normals.png"
cmp -s "$tmp/look-clay.png" "$tmp/default.png" || fail "--look clay is not the default look"
rc=0
run --look chrome --hide-ui 2>/dev/null || rc=$?
[ "$rc" = 2 ] || fail "an unknown look exited $rc, not 2"

# --- the panel at the default window size: every label fits its width, Add clay among the
#     tools (the modeler reports any item cut off, src/app/modeler.cpp mustFit) -----------
ASAN_OPTIONS=$app_asan "$app" --voxel-size 0.03125 --screenshot "$tmp/panel.png" \
  --replay-input "$tmp/none.json" 2>"$tmp/panel.err"
if grep -q "does not fit" "$tmp/panel.err"; then fail "$(cat "$tmp/panel.err")"; fi
"$py" - "$tmp/panel.png" <<'PY'
from PIL import Image
im = Image.open(__import__("sys").argv[1])
assert im.size == (1280, 800), im.size  # the default window
PY
echo "panel: every label fits at the default window size"

# --- an idle window draws nothing: with no input and nothing running it waits for input
#     (redrawing the same picture kept one and a half cores busy under Mesa) -------------
ASAN_OPTIONS=$app_asan "$app" --size 640x480 --voxel-size 0.03125 --session-dir "$tmp/idle" \
    2>"$tmp/idle.err" &
idle=$!
ticks() {
  kill -0 "$idle" 2>/dev/null || { cat "$tmp/idle.err"; fail "the idle window ended"; }
  awk '{print $14 + $15}' "/proc/$idle/stat"
}
quiet=0 # once started, a second in which it used at most 5% of a core
for _ in $(seq 30); do
  before=$(ticks)
  sleep 1
  used=$(($(ticks) - before))
  if [ "$used" -le $(($(getconf CLK_TCK) / 20)) ]; then quiet=1; break; fi
done
kill "$idle"
wait "$idle" || true
[ "$quiet" = 1 ] || fail "the idle window kept drawing: $used clock ticks in its last second"
echo "idle window: $used clock ticks in a second"

# --- a script that dents the side facing the camera: the picture changes there ----------
run --hide-ui --script "$here/dent.json" --screenshot "$tmp/dent.png"
"$py" "$here/check_image.py" changed "$tmp/default.png" "$tmp/dent.png"

# --- a replayed drag pulls the surface out; the recorded script replays to the same grid.
#     No --size: the window is the one the file names, where its clicks reach the sphere.
ASAN_OPTIONS=$app_asan "$app" --voxel-size 0.03125 --replay-input "$here/drag_a.json" \
    --save "$tmp/a.vdb" --save-script "$tmp/a.json" --screenshot "$tmp/a.png" \
    --latency-report --latency-csv "$tmp/latency.csv" 2>"$tmp/latency"
cat "$tmp/latency"
check_latency() {
  "$py" - "$@" <<'PY'
import csv, re, sys
text = open(sys.argv[1]).read()
m = re.search(r"latency over (\d+) segments", text)
rows = list(csv.DictReader(open(sys.argv[2])))
assert m and int(m.group(1)) == len(rows) >= 3, (text, len(rows))
# Every segment's latency, from its drag event to its mesh on screen, holds its own work
# (advect, renormalize, re-mesh) and the frame that shows it (upload, then draw); figures
# are printed to 1e-4 ms. That frame uploaded the segment's mesh (some bricks of it).
for r in rows:
    r = {k: float(v) for k, v in r.items()}
    work = r["advect"] + r["renorm"] + r["mesh"]
    assert work > 0 and r["draw"] > 0 and r["upload"] >= 0, r
    assert r["bricks"] > 0, ("a segment's frame showed an older mesh", r)
    assert r["total"] + 1e-3 >= work + r["upload"] + r["draw"], r
PY
}
check_latency "$tmp/latency" "$tmp/latency.csv"
"$cli" info --json "$tmp/default.vdb" >"$tmp/default.info"
"$cli" info --json "$tmp/a.vdb" >"$tmp/a.info"
"$py" - "$tmp/default.info" "$tmp/a.info" <<'PY'
import json, sys
before, after = (json.load(open(p)) for p in sys.argv[1:3])
print(f"volume {before['volume']:.5f} -> {after['volume']:.5f}, triangles "
      f"{before['mesh_triangles']} -> {after['mesh_triangles']}")
assert after["volume"] > 1.01 * before["volume"], "the drag did not pull the surface out"
assert after["mesh_triangles"] != before["mesh_triangles"]
PY
"$cli" apply "$tmp/a.json" -o "$tmp/a_replayed.vdb" -q
"$py" "$here/same_grid.py" "$tmp/a.vdb" "$tmp/a_replayed.vdb"

# --- a window other than the one a replay names: said; a report with nothing sculpted says
#     so instead of printing zeros
echo '{"window": [640, 480], "events": []}' >"$tmp/named.json"
ASAN_OPTIONS=$app_asan "$app" --size 800x600 --voxel-size 0.03125 --hide-ui \
    --replay-input "$tmp/named.json" --latency-report 2>"$tmp/named.err"
grep -q "was recorded in a 640x480 window; in this 800x600 one" "$tmp/named.err" ||
  { cat "$tmp/named.err"; fail "no word of the replay's other window"; }
grep -q "^latency: nothing was sculpted" "$tmp/named.err" ||
  { cat "$tmp/named.err"; fail "a report of nothing sculpted"; }
cat "$tmp/named.err"

# --- the same drag at frame pace, sculpting off the render thread (events coalesced):
#     whatever was applied is in the script, which replays to the same grid; each piece's
#     mesh is on screen in the frame after it ends, though the next piece starts at once --
run --replay-input "$here/long_drag.json" --replay-live --save "$tmp/live.vdb" \
    --save-script "$tmp/live.json" --latency-report --latency-csv "$tmp/live.csv" \
    2>"$tmp/live.err"
cat "$tmp/live.err"
check_latency "$tmp/live.err" "$tmp/live.csv"
"$cli" apply "$tmp/live.json" -o "$tmp/live_replayed.vdb" -q
"$py" "$here/same_grid.py" "$tmp/live.vdb" "$tmp/live_replayed.vdb"
"$py" -c 'import json,sys; p=json.load(open(sys.argv[1]))["strokes"][0]["tools"][0]["path"]; print(f"live drag: {len(p) - 1} segments for 61 events"); assert len(p) >= 3' "$tmp/live.json"

# --- the volume-preserving swirl drag keeps the volume; a dab of clay adds some ---------
run --replay-input "$here/swirl_and_clay.json" --save "$tmp/swirl.vdb" --save-script "$tmp/swirl.json"
"$cli" info --json "$tmp/swirl.vdb" >"$tmp/swirl.info"
"$py" - "$tmp/default.info" "$tmp/swirl.info" "$tmp/swirl.json" <<'PY'
import json, sys
before, after = (json.load(open(p)) for p in sys.argv[1:3])
strokes = json.load(open(sys.argv[3]))["strokes"]
swirls = [s for s in strokes if s["type"] == "swirl"]
dabs = [s for s in strokes if s["type"] == "inflate"]
assert len(swirls) >= 5 and len(dabs) == 1, [s["type"] for s in strokes]
r = dabs[0]["radius"]
ball = 4.0 / 3.0 * 3.141592653589793 * r ** 3
gain = after["mesh_volume"] - before["mesh_volume"]
print(f"{len(swirls)} swirls and a dab of clay (ball {ball:.5f}): volume {gain:+.5f}")
# The swirls move clay without adding any; the dab adds about its ball.
assert abs(gain - ball) < 0.1 * ball, (gain, ball)
PY
"$cli" apply "$tmp/swirl.json" -o "$tmp/swirl_replayed.vdb" -q
"$py" "$here/same_grid.py" "$tmp/swirl.vdb" "$tmp/swirl_replayed.vdb"

# --- pinch mode (P): a press on the sphere and a drag poke a hole through it along the
# view; the saved shape is a torus (that the recorded script replays to it is checked
# without a window, by SculptController.EveryReplayFileSculptsAndRecords...). At 1/32 (see
# run): the pinch's hundreds of sub-steps take most of a minute at 1/64 under the sanitizers.
run --replay-input "$here/pinch.json" --save "$tmp/pinch.vdb" \
    --save-script "$tmp/pinch.json"
"$cli" info --json "$tmp/pinch.vdb" >"$tmp/pinch.info"
"$py" - "$tmp/pinch.info" "$tmp/pinch.json" <<'PY'
import json, sys
info, script = (json.load(open(p)) for p in sys.argv[1:3])
assert [s["type"] for s in script["strokes"]] == ["pinch"], script["strokes"]
assert info["euler_characteristic"] == 0 and info["components"] == 1, info
print(f"pinch: a torus (genus {info['genus']}), hole radius {script['strokes'][0]['open']:.3f}")
PY

# --- what artists' hands bring: Shift-drag smooths, Ctrl-drag inverts inflate, Ctrl-click
# takes away the clay a click added, F sizes the brush in the view and Shift-F its strength
run --replay-input "$here/artist_habits.json" --save "$tmp/habits.vdb" \
    --save-script "$tmp/habits.json" --screenshot "$tmp/habits.png"
"$py" - "$tmp/habits.json" <<'PY'
import json, sys
strokes = json.load(open(sys.argv[1]))["strokes"]
kinds = [s["type"] for s in strokes]
smooth = [s for s in strokes if s["type"] == "smooth"]
sweeps = [s for s in strokes if s["type"] == "sweep"]
clay = [s for s in strokes if s["type"] == "inflate"]
assert len(smooth) >= 3 and len(sweeps) == 2 and len(clay) == 2, kinds
deflate = sweeps[0]["tools"][0]["path"][-1]["s"]
assert all(v < 1 for v in (deflate if isinstance(deflate, list) else [deflate])), deflate
assert "remove" not in clay[0] and clay[1]["remove"] is True, clay
grab = sweeps[1]
assert abs(grab["strength"] - 0.5) < 1e-9, grab
assert grab["tools"][0]["size"] > 0.4, grab["tools"][0]["size"]  # F: 80 pixels, not 0.25
print(f"habits: {len(smooth)} smooth dabs, a deflation (scale {deflate}), clay added and "
      f"taken away, a grab of radius {grab['tools'][0]['size']:.3f} at strength 0.5")
PY
"$cli" apply "$tmp/habits.json" -o "$tmp/habits_replayed.vdb" -q
"$py" "$here/same_grid.py" "$tmp/habits.vdb" "$tmp/habits_replayed.vdb"
# The same hands under a work limit no smooth dab fits: the dabs are refused (the status
# line says why), every other stroke is kept.
run --replay-input "$here/artist_habits.json" --max-work 1000 --save-script "$tmp/limited.json"
"$py" - "$tmp/habits.json" "$tmp/limited.json" <<'PY'
import json, sys
full, limited = ([s["type"] for s in json.load(open(p))["strokes"]] for p in sys.argv[1:3])
assert "smooth" not in limited and limited == [k for k in full if k != "smooth"], (full, limited)
print(f"habits under --max-work 1000: {len(full) - len(limited)} smooth dabs refused, "
      f"{len(limited)} strokes kept")
PY

# --- two strokes, undo both, redo one: the grid after the first stroke, exactly --------
run --replay-input "$here/drag_ab_undo.json" --save "$tmp/undo.vdb" --save-script "$tmp/undo.json"
"$py" "$here/same_grid.py" "$tmp/a.vdb" "$tmp/undo.vdb"
"$py" -c 'import json,sys; n=len(json.load(open(sys.argv[1]))["strokes"]); assert n == 1, n' \
    "$tmp/undo.json"

# --- the replay files recorded above frame by frame, through the controller without a
# window: the same script (long_drag, replayed live above, goes through the controller in
# SculptController.EveryReplayFileSculptsAndRecordsAScriptThatReplaysExactly)
cp "$tmp/a.json" "$tmp/windowed_drag_a.json"
cp "$tmp/undo.json" "$tmp/windowed_drag_ab_undo.json"
cp "$tmp/swirl.json" "$tmp/windowed_swirl_and_clay.json"
cp "$tmp/habits.json" "$tmp/windowed_artist_habits.json"
for events in drag_a drag_ab_undo swirl_and_clay artist_habits; do
  "$headless" "$here/$events.json" 640 480 0.03125 "$tmp/headless_$events.json"
  cmp "$tmp/windowed_$events.json" "$tmp/headless_$events.json" ||
    fail "$events: the controller without a window recorded another script"
  echo "$events: the same script with and without a window"
done

# --- bad files dropped on the window: a clear error, the document kept ----------------
"$py" - "$tmp/fog.vdb" <<'PY'
import sys, pyopenvdb as vdb
g = vdb.FloatGrid()
g.gridClass = vdb.GridClass.FOG_VOLUME
g.name = "density"
g.fill((0, 0, 0), (7, 7, 7), 1.0)
vdb.write(sys.argv[1], grids=[g])
PY
head -c 300 /dev/urandom >"$tmp/corrupt.vdb"
echo '{"sweepers": 1, "strokes": [{"type": "bend"}]}' >"$tmp/bad.json"
for bad in fog.vdb corrupt.vdb bad.json; do
  printf '{"events": [{"frame": 2, "type": "drop", "path": "%s"}]}' "$tmp/$bad" >"$tmp/drop.json"
  run --replay-input "$tmp/drop.json" --save "$tmp/kept.vdb" 2>"$tmp/err" || fail "$bad: exit code"
  grep -q "^sweepers: .*$bad" "$tmp/err" || { cat "$tmp/err"; fail "$bad: no clear message"; }
  "$py" "$here/same_grid.py" "$tmp/default.vdb" "$tmp/kept.vdb" >/dev/null
  echo "$bad: $(head -n1 "$tmp/err")"
done

# --- files that crashed the readers, dropped one after another in one session: the session
# lives on (OpenVDB's reader runs in a child process; mesh indices are checked before
# Assimp post-processes them), every one gets its message, the document is kept
"$cli" new -o "$tmp/small.vdb" --voxel-size 0.1 --radius 0.5
"$py" "$here/../cli/mutate.py" "$tmp/small.vdb" "$tmp/damaged" 12 7
for f in "$tmp"/damaged/*.vdb; do # the ones that still read would open: keep the others
  if "$cli" info "$f" >/dev/null 2>&1; then rm "$f"; fi
done
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 -5\n' >"$tmp/damaged/negative.ply"
"$py" - "$tmp/damaged" "$tmp/drops.json" <<'PY'
import json, os, sys
files = sorted(os.path.join(sys.argv[1], f) for f in os.listdir(sys.argv[1]))
events = [{"frame": 2 + 2 * k, "type": "drop", "path": f} for k, f in enumerate(files)]
json.dump({"events": events}, open(sys.argv[2], "w"))
PY
run --replay-input "$tmp/drops.json" --save "$tmp/kept.vdb" 2>"$tmp/err" ||
  { cat "$tmp/err"; fail "the session did not survive the damaged files"; }
grep -q "negative.ply: face 3 refers to vertex -5" "$tmp/err" || fail "no message for the PLY"
[ "$(grep -c "^sweepers: .*damaged/" "$tmp/err")" = "$(ls "$tmp/damaged" | wc -l)" ] ||
  fail "not every damaged file got its message"
"$py" "$here/same_grid.py" "$tmp/default.vdb" "$tmp/kept.vdb" >/dev/null
echo "damaged files dropped: $(grep -c "^sweepers: .*damaged/" "$tmp/err") refused, the session kept"

# --- started on a bad file: one line, non-zero exit ---------------------------------------
if run "$tmp/fog.vdb" --replay-input "$tmp/none.json" 2>"$tmp/err"; then fail "fog volume opened"; fi
grep -q "^sweepers: " "$tmp/err" || fail "no message for a bad start file"
# --- kill -9 in the middle of a session, then --recover: the grid a clean run saves after
# the same completed strokes, voxel for voxel ---------------------------------------------
# The clean run: strokes with an undo that outlives a checkpoint, a redo; a checkpoint every
# two strokes. It ends cleanly, so its session is removed.
run --replay-input "$here/session_drags.json" --session-dir "$tmp/sessions" \
    --checkpoint-every 2 --save "$tmp/clean.vdb" --save-script "$tmp/clean.json"
[ -z "$(ls -A "$tmp/sessions")" ] || fail "a clean end left its session behind"
strokes=$("$py" -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["strokes"]))' \
          "$tmp/clean.json")
# No memory for undo: both undos rebuild the grid from a checkpoint (or the start) off the
# render thread, the redo applies the edit again; the same grid and script.
run --replay-input "$here/session_drags.json" --session-dir "$tmp/sessions" \
    --checkpoint-every 2 --undo-budget 0 --save "$tmp/replayed_undo.vdb" \
    --save-script "$tmp/replayed_undo.json"
"$py" "$here/same_grid.py" "$tmp/clean.vdb" "$tmp/replayed_undo.vdb"
cmp "$tmp/clean.json" "$tmp/replayed_undo.json" || fail "undo by replay: another script"
# The same events, then the modeler waits (an event far ahead) and is killed once the
# journal holds every edit (6 edits, 2 undos).
"$py" -c 'import json,sys; e=json.load(open(sys.argv[1])); e["events"].append({"frame": 10**6, "type": "scroll", "dy": 0}); json.dump(e, open(sys.argv[2], "w"))' \
    "$here/session_drags.json" "$tmp/keepalive.json"
ASAN_OPTIONS=$app_asan "$app" --size 640x480 --voxel-size 0.03125 --replay-input "$tmp/keepalive.json" --session-dir "$tmp/sessions" \
    --checkpoint-every 2 &
pid=$! # the modeler itself, not a shell around it
for _ in $(seq 600); do
  j=$(ls "$tmp"/sessions/*/journal 2>/dev/null | head -n1 || true)
  [ -n "$j" ] && [ "$(grep -c '"append"\|"truncate"' "$j")" = 8 ] && break
  sleep 0.1
done
kill -9 $pid
wait $pid 2>/dev/null || true
[ "$(ls "$tmp/sessions" | wc -l)" = 1 ] || fail "the killed session is not on disk"
cp -a "$tmp/sessions" "$tmp/sessions_copy"
# A batch run does not offer the recovery, and leaves the interrupted session alone.
run --replay-input "$tmp/none.json" --session-dir "$tmp/sessions" --save "$tmp/fresh.vdb"
"$py" "$here/same_grid.py" "$tmp/default.vdb" "$tmp/fresh.vdb" >/dev/null
[ "$(ls "$tmp/sessions" | wc -l)" = 1 ] || fail "the interrupted session was touched"
run --recover --replay-input "$tmp/none.json" --session-dir "$tmp/sessions" \
    --save "$tmp/recovered.vdb" --save-script "$tmp/recovered.json" 2>"$tmp/err"
cat "$tmp/err"
grep -q "^sweepers: recovered $strokes strokes (from the checkpoint after stroke" "$tmp/err" ||
  fail "no recovery report"
"$py" "$here/same_grid.py" "$tmp/clean.vdb" "$tmp/recovered.vdb"
cmp "$tmp/clean.json" "$tmp/recovered.json" || fail "the recovered script differs"
[ -z "$(ls -A "$tmp/sessions")" ] || fail "the recovered session was left behind"
# The command line rebuilds the same document from the session as the crash left it.
"$cli" recover "$tmp/sessions_copy" -o "$tmp/cli_recovered.vdb" 2>"$tmp/err"
grep -q ": recovered $strokes strokes" "$tmp/err" || { cat "$tmp/err"; fail "sweepers-cli recover"; }
"$py" "$here/same_grid.py" "$tmp/clean.vdb" "$tmp/cli_recovered.vdb"
run --recover --replay-input "$tmp/none.json" --session-dir "$tmp/sessions" 2>"$tmp/err"
grep -qx "sweepers: there is no interrupted session to recover" "$tmp/err" ||
  fail "--recover without a session: '$(cat "$tmp/err")'"

echo "all modeler checks passed"

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# sweepers-cli recover on session journals written here by hand, as a modeler that died
# would leave them: the history they hold (undo included) rebuilt to the grid that
# `apply` makes of the same strokes; a record cut short by the crash or a damaged one; and
# every refusal, each with its exact message.
. "$(dirname "$0")/common.sh" "$@"
here=$(cd "$(dirname "$0")" && pwd)

# A session of four edits and an undo, at a coarse voxel size: a sweep, two swirls, a dab
# of clay (undone), one more swirl. expected.json holds the history it leaves.
mkdir -p "$tmp/sessions/a"
"$py" - "$data" "$tmp/sessions/a/journal" "$tmp/expected.json" <<'PY'
import json, sys
data, journal, expected = sys.argv[1:4]
pull = json.load(open(f"{data}/pull.json"))["strokes"][0]
swirls = json.load(open(f"{data}/starfish_swirls.json"))["strokes"][:3]
start = {"sweepers": 1, "grid": {"voxel_size": 0.04, "half_width": 3},
         "start": {"sphere": {"center": [0, 0, 0], "radius": 1}}, "strokes": []}
dab = {"type": "inflate", "at": [0, 1, 0], "radius": 0.2}
records = [{"session": 1, "dir": data, "script": start},
           {"append": [pull]}, {"append": swirls[:2]}, {"append": [dab]},
           {"truncate": 3}, {"append": [swirls[2]]}]
with open(journal, "w") as f:
    for r in records:
        f.write(json.dumps(r) + "\n")
json.dump(dict(start, strokes=[pull] + swirls), open(expected, "w"))
PY
"$cli" apply "$tmp/expected.json" -o "$tmp/expected.vdb" -q
"$cli" recover "$tmp/sessions/a" -o "$tmp/recovered.vdb" --script "$tmp/recovered.json" \
    2>"$tmp/err"
[ "$(cat "$tmp/err")" = "$tmp/sessions/a: recovered 4 strokes (replayed from the start)" ] ||
  fail "report: $(cat "$tmp/err")"
"$py" "$here/../app/same_grid.py" "$tmp/expected.vdb" "$tmp/recovered.vdb"
"$py" - "$tmp/expected.json" "$tmp/recovered.json" <<'PY'
import json, sys
a, b = (json.load(open(p))["strokes"] for p in sys.argv[1:3])
assert len(a) == len(b) == 4 and [s["type"] for s in a] == [s["type"] for s in b], (a, b)
PY
# A directory of sessions: the newest interrupted one (nobody holds its lock) is taken.
"$cli" recover "$tmp/sessions" -o "$tmp/newest.vdb" 2>/dev/null
"$py" "$here/../app/same_grid.py" "$tmp/expected.vdb" "$tmp/newest.vdb" >/dev/null

# The crash came while the last record was written: the history before it.
cp -r "$tmp/sessions/a" "$tmp/torn"
"$py" -c 'import sys; p=sys.argv[1]; t=open(p).read(); open(p, "w").write(t[:-15])' \
    "$tmp/torn/journal"
"$cli" recover "$tmp/torn" -o "$tmp/torn.vdb" 2>"$tmp/err"
[ "$(cat "$tmp/err")" = "$tmp/torn: recovered 3 strokes (replayed from the start); the last record was cut short by the crash (ignored)" ] ||
  fail "torn: $(cat "$tmp/err")"
echo "torn: $(cat "$tmp/err")"

# Damage in the middle (a stroke of an unknown type): the history before it, said so.
cp -r "$tmp/sessions/a" "$tmp/damaged"
sed -i '3s/"swirl"/"twirl"/' "$tmp/damaged/journal"
"$cli" recover "$tmp/damaged" -o "$tmp/damaged.vdb" 2>"$tmp/err"
[ "$(cat "$tmp/err")" = "$tmp/damaged: recovered 1 stroke (replayed from the start); the journal is damaged at line 3; what follows was left out" ] ||
  fail "damaged: $(cat "$tmp/err")"
echo "damaged: $(cat "$tmp/err")"

# A checkpoint that cannot be read is skipped: the history is replayed from the start.
cp -r "$tmp/sessions/a" "$tmp/badcheckpoint"
head -c 200 "$tmp/expected.vdb" >"$tmp/badcheckpoint/checkpoint-1.vdb"
echo '{"checkpoint": "checkpoint-1.vdb", "strokes": 4}' >>"$tmp/badcheckpoint/journal"
"$cli" recover "$tmp/badcheckpoint" -o "$tmp/badcheckpoint.vdb" 2>"$tmp/err"
grep -q "^$tmp/badcheckpoint: recovered 4 strokes (replayed from the start); a checkpoint was skipped: $tmp/badcheckpoint/checkpoint-1.vdb: " "$tmp/err" ||
  fail "bad checkpoint: $(cat "$tmp/err")"
"$py" "$here/../app/same_grid.py" "$tmp/expected.vdb" "$tmp/badcheckpoint.vdb" >/dev/null

# Refusals, each in one line; nothing is written.
mkdir -p "$tmp/empty" "$tmp/notajournal"
echo '{"sweepers": 1, "strokes": []}' >"$tmp/notajournal/journal"
refuses "sweepers-cli: $tmp/nowhere: no such session directory" \
  recover "$tmp/nowhere" -o "$tmp/out.vdb"
refuses "sweepers-cli: $tmp/empty: there is no interrupted session to recover" \
  recover "$tmp/empty" -o "$tmp/out.vdb"
refuses "sweepers-cli: $tmp/notajournal/journal: cannot recover from this journal (not a session journal)" \
  recover "$tmp/notajournal" -o "$tmp/out.vdb"
refuses "sweepers-cli: $tmp/no/out.vdb: cannot write there ($tmp/no is not a writable directory)" \
  recover "$tmp/sessions/a" -o "$tmp/no/out.vdb"
[ ! -e "$tmp/out.vdb" ] || fail "a refused recovery wrote a file"
echo "all recover checks passed"

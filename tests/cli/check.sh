#!/usr/bin/env bash
# sweepers-cli check on real scripts: a valid one prints its plan, a bad one fails with one
# line on stderr that names the file, the location and the reason.
. "$(dirname "$0")/common.sh" "$@"

"$cli" check "$data/pull.json" >"$tmp/out"
grep -q "segment 0: 1 tool(s), 2 sub-steps" "$tmp/out" || { cat "$tmp/out"; exit 1; }
"$cli" check --json "$data/pull.json" | /usr/bin/python3 -c '
import json, sys
report = json.load(sys.stdin)
plan = report["deformations"]
assert report["valid"] and report["strokes"] == 1, report
assert len(plan) == 2 and all(p["steps"] == 2 for p in plan), plan'

printf '{"sweepers": 1, "strokes": [{"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": -1, "path": []}]}]}' >"$tmp/bad.json"
if "$cli" check "$tmp/bad.json" >"$tmp/out" 2>"$tmp/err"; then
  echo "a bad script was accepted"; exit 1
fi
[ "$(wc -l <"$tmp/err")" -eq 1 ] || { echo "expected one line:"; cat "$tmp/err"; exit 1; }
grep -q "bad.json: /strokes/0/tools/0/falloff: must be positive" "$tmp/err" || { cat "$tmp/err"; exit 1; }
[ ! -s "$tmp/out" ] || { echo "unexpected stdout"; cat "$tmp/out"; exit 1; }

if "$cli" check "$tmp/missing.json" 2>"$tmp/err"; then echo "a missing file was accepted"; exit 1; fi
grep -q "missing.json: cannot open" "$tmp/err"
echo "check: ok"
